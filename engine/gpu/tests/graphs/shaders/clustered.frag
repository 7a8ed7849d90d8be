#version 450
#extension GL_KHR_shader_subgroup_clustered : require
layout(push_constant) uniform Params { vec4 color; } params;
layout(location = 0) out vec4 color;

void main() {
    // A cluster of one lane: the sum is the lane's own value.
    color = params.color * subgroupClusteredAdd(1.0, 1u);
}
