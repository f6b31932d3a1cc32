// The EXACT_LIST dispatch's size from the count its listing pass left (light_pass.glsl's
// ExactCount), written where glDispatchComputeIndirect reads it: work groups of 64 in rows of at
// most 65535 (the smallest GL_MAX_COMPUTE_WORK_GROUP_COUNT), sized on the GPU so that no frame
// reads the count back.
#version 450 core
layout(local_size_x = 1) in;
layout(std430, binding = 0) readonly buffer ExactCount { uint count; };
layout(std430, binding = 4) writeonly buffer DispatchArgs { uint groups[3]; };
void main() {
  const uint n = (count + 63u) / 64u, row = min(n, 65535u);
  groups[0] = row;
  groups[1] = row == 0u ? 0u : (n + row - 1u) / row;
  groups[2] = 1u;
}
