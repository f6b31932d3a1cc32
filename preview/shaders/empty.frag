// Shadow maps hold depth only: their fragments write nothing else.
#version 450 core
void main() {}
