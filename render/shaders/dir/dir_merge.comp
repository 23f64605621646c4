#version 450
// Differential instant radiosity, merge pass (render/dir_vk.h): the geometry-aware blur that
// turns interleaved indirect light back into a full image (Segovia et al. 2006; Knecht 2010 §4).
// Each pixel averages the indirect light of the n x n window [x - n/2, x + n/2 - 1] (one pixel of
// every VPL subset) over the neighbours on the same kind of surface (real or virtual) within 5 %
// of its distance and with normals within ~25 degrees; a subset whose pixel there fails is
// looked for one period further out (its 8 pixels at ±n), averaged first, so that each subset
// found counts once. Direct light passes through unblurred; the merged indirect light takes the
// pixel's k_d texture factor (in the w of its shaded vec4s 1-3, dir_shade.comp).
// The CPU mirror is merged_pixel() in dir_maps_cpu.cpp.
layout(local_size_x = 8, local_size_y = 8) in;

layout(std430, set = 0, binding = 0) readonly buffer GBuffer { vec4 gbuffer[]; };
layout(std430, set = 0, binding = 1) readonly buffer Shaded { vec4 shaded[]; };  // 4 per pixel
// 4 per pixel: L_rv (w: virtual coverage), L_r, and their indirect parts.
layout(std430, set = 0, binding = 2) writeonly buffer Radiance { vec4 radiance[]; };

layout(push_constant) uniform Params {
  uint width;
  uint height;
  uint interleave;
} params;

bool similar(ivec2 q, ivec2 size, uint pixels, float distance, vec3 normal) {
  if (q.x < 0 || q.y < 0 || q.x >= size.x || q.y >= size.y) return false;
  const uint j = uint(q.y) * params.width + uint(q.x);
  const float dq = gbuffer[j].w;
  if (dq == 0.0 || (dq < 0.0) != (distance < 0.0)) return false;
  if (abs(abs(dq) - abs(distance)) > 0.05 * abs(distance)) return false;
  return dot(gbuffer[pixels + j].xyz, normal) >= 0.9;
}

void main() {
  const ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  const ivec2 size = ivec2(params.width, params.height);
  if (p.x >= size.x || p.y >= size.y) return;
  const uint pixels = params.width * params.height;
  const uint i = uint(p.y) * params.width + uint(p.x);
  const vec4 position = gbuffer[i];
  const vec3 normal = gbuffer[pixels + i].xyz;
  vec3 sum_rv = shaded[4u * i + 2u].xyz, sum_r = shaded[4u * i + 3u].xyz;
  float weight = 1.0;
  const int n = int(params.interleave);
  if (n > 1 && position.w != 0.0) {
    for (int dy = -n / 2; dy < n - n / 2; ++dy)
      for (int dx = -n / 2; dx < n - n / 2; ++dx) {
        if (dx == 0 && dy == 0) continue;
        const ivec2 q = p + ivec2(dx, dy);
        if (similar(q, size, pixels, position.w, normal)) {
          const uint j = uint(q.y) * params.width + uint(q.x);
          sum_rv += shaded[4u * j + 2u].xyz;
          sum_r += shaded[4u * j + 3u].xyz;
          weight += 1.0;
          continue;
        }
        vec3 subset_rv = vec3(0.0), subset_r = vec3(0.0);
        float found = 0.0;
        for (int b = -1; b <= 1; ++b)
          for (int a = -1; a <= 1; ++a) {
            const ivec2 s = q + ivec2(a, b) * n;
            if ((a == 0 && b == 0) || !similar(s, size, pixels, position.w, normal)) continue;
            const uint j = uint(s.y) * params.width + uint(s.x);
            subset_rv += shaded[4u * j + 2u].xyz;
            subset_r += shaded[4u * j + 3u].xyz;
            found += 1.0;
          }
        if (found == 0.0) continue;
        sum_rv += subset_rv / found;
        sum_r += subset_r / found;
        weight += 1.0;
      }
  }
  const vec4 direct_rv = shaded[4u * i];
  const vec3 kd_texture = vec3(shaded[4u * i + 1u].w, shaded[4u * i + 2u].w, shaded[4u * i + 3u].w);
  const vec3 indirect_rv = sum_rv / weight * kd_texture, indirect_r = sum_r / weight * kd_texture;
  radiance[4u * i] = vec4(direct_rv.xyz + indirect_rv, direct_rv.w);
  radiance[4u * i + 1u] = vec4(shaded[4u * i + 1u].xyz + indirect_r, 0.0);
  radiance[4u * i + 2u] = vec4(indirect_rv, 0.0);
  radiance[4u * i + 3u] = vec4(indirect_r, 0.0);
}
