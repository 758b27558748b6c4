#version 450 core
// Depth only: the fixed-function depth write is the shadow map.
void main() {}
