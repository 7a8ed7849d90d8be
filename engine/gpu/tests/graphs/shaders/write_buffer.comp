#version 450
layout(local_size_x = 1) in;
layout(binding = 0) buffer Data { vec4 v; } src_buf;
layout(push_constant) uniform Params { vec4 value; } params;

void main() {
    src_buf.v = params.value;
}
