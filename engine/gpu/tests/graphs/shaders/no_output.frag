#version 450
// A fragment shader for a depth-only pass: it writes no colour.
void main() {
}
