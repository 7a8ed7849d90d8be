#version 450
// Writes one output although its pass has two colour attachments.
layout(location = 0) out vec4 color;

void main() {
    color = vec4(1.0);
}
