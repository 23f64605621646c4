// Shared by the DIR compute shaders; each function mirrors the C++ function named beside it.
#include "basis.glsl"

const float EMPTY = 1e30;  // kShadowEmpty (shadow_maps.h)
const float PI = 3.14159265358979;

struct Vpl {  // vpl_buffer.h: GpuVpl
  vec4 position_material;  // w: material index (bits)
  vec4 normal_flags;       // w: bit 0 r(VPL), bit 1 in_real_virtual, bit 2 in_real, bit 3 emitter (bits)
  vec4 incident;    // w: Vpl::metallic_roughness.y (roughness texel)
  vec4 flux;        // w: Vpl::metallic_roughness.z (metallic texel)
  vec4 kd_texture;  // Vpl::kd_texture
};

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

// TileProjection (ism.h): a VPL tile's mapping, the hemisphere's paraboloid (tan_half = 0) or a
// perspective view of the cone around the virtual objects' bounding sphere.
struct Projection {
  vec3 origin, t, b, n;
  float tan_half;
};

Projection hemisphere(Vpl vpl) {
  Projection p;
  p.origin = vpl.position_material.xyz;
  p.n = vpl.normal_flags.xyz;
  orthonormal_basis(p.n, p.t, p.b);
  p.tan_half = 0.0;
  return p;
}

Projection towards(Vpl vpl, vec4 sphere) {
  const vec3 to_centre = sphere.xyz - vpl.position_material.xyz;
  const float distance = length(to_centre), radius = sphere.w;
  if (!(radius > 0.0) || distance <= 1.05 * radius) return hemisphere(vpl);
  Projection p;
  p.origin = vpl.position_material.xyz;
  p.n = to_centre / distance;
  orthonormal_basis(p.n, p.t, p.b);
  p.tan_half = radius / sqrt(distance * distance - radius * radius);
  return p;
}

bool is_emitter(Vpl vpl) { return (floatBitsToUint(vpl.normal_flags.w) & 8u) != 0u; }

// TileProjection::real_tile / virtual_tile (ism.h): an emitter's tiles look at the scene.
Projection real_tile(Vpl vpl, vec4 scene_bounds) { return is_emitter(vpl) ? towards(vpl, scene_bounds) : hemisphere(vpl); }

Projection virtual_tile(Vpl vpl, vec4 virtual_bounds, vec4 scene_bounds) {
  return towards(vpl, is_emitter(vpl) && !(virtual_bounds.w > 0.0) ? scene_bounds : virtual_bounds);
}

vec3 projection_local(Projection p, vec3 point, out float distance) {
  const vec3 q = point - p.origin;
  distance = length(q);
  return vec3(dot(q, p.t), dot(q, p.b), dot(q, p.n)) / distance;
}

bool projection_texel(Projection p, vec3 d, int tile, out vec2 coordinates) {
  if (p.tan_half == 0.0) {
    coordinates = paraboloid_texel(d, tile);
    return true;
  }
  coordinates = vec2(0.0);
  if (d.z <= 0.0) return false;
  coordinates = (d.xy * (1.0 / (d.z * p.tan_half)) * 0.5 + 0.5) * float(tile);
  return all(greaterThanEqual(coordinates, vec2(0.0))) && all(lessThan(coordinates, vec2(tile)));
}

vec3 projection_direction(Projection p, vec2 coordinates, int tile) {
  if (p.tan_half == 0.0) return paraboloid_direction(coordinates, tile);
  return normalize(vec3((coordinates / float(tile) * 2.0 - 1.0) * p.tan_half, 1.0));
}

float texel_angle(Projection p, int tile) { return p.tan_half == 0.0 ? 4.0 / float(tile) : 2.0 * p.tan_half / float(tile); }

// ism_point_index() (ism.h) in 32 bits: (vpl * 7919 + i) mod pool, exact for pools of at most
// 2^16 points (validated on the host).
uint ism_point_index(uint vpl, uint i, uint pool) {
  return ((vpl % pool) * (7919u % pool) % pool + i % pool) % pool;
}
