// Shared by the DIR compute shaders; each function mirrors the C++ function named beside it.
const float EMPTY = 1e30;  // kShadowEmpty (shadow_maps.h)
const float PI = 3.14159265358979;

struct Vpl {  // vpl_buffer.h: GpuVpl
  vec4 position_material;  // w: material index (bits)
  vec4 normal_flags;       // w: bit 0 r(VPL), bit 1 in_real_virtual, bit 2 in_real (bits)
  vec4 incident;
  vec4 flux;
};

// orthonormal_basis() (phong_brdf.h), Duff et al. 2017.
void orthonormal_basis(vec3 n, out vec3 t, out vec3 b) {
  const float s = n.z >= 0.0 ? 1.0 : -1.0;
  const float a = -1.0 / (s + n.z);
  const float c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}

// paraboloid_texel() (ism.h).
vec2 paraboloid_texel(vec3 d, int tile) {
  const float scale = 1.0 / (1.0 + max(d.z, 0.0));
  return (d.xy * scale * 0.5 + 0.5) * float(tile);
}

// paraboloid_direction() (ism.h): the unit direction through texel coordinates.
vec3 paraboloid_direction(vec2 texel, int tile) {
  const vec2 uv = texel / float(tile) * 2.0 - 1.0;
  const float r2 = dot(uv, uv);
  return vec3(uv * (2.0 / (1.0 + r2)), (1.0 - r2) / (1.0 + r2));
}

// ism_point_index() (ism.h) in 32 bits: (vpl * 7919 + i) mod pool, exact for pools of at most
// 2^16 points (validated on the host).
uint ism_point_index(uint vpl, uint i, uint pool) {
  return ((vpl % pool) * (7919u % pool) % pool + i % pool) % pool;
}
