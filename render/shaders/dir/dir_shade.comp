#version 450
// Differential instant radiosity, shading pass (render/dir_vk.h; Knecht et al. 2010, eqs.
// 5.1-5.8): one invocation per G-buffer pixel computes L_rv and L_r together from the same
// primary lights and VPLs. The CPU mirror is shade_dir_from_maps() (dir_vk.h).
//   direct    L_rv += L_o min(V_r, V_v)              L_r += L_o r(light) r(p) V_r
//   indirect  L_rv += L_o (1 - ir(VPL)) min(V_r, V_v)  L_r += L_o r(x̄) r(VPL) r(p) V_r
// V_r / V_v come from the shadow-map atlas (primary lights) and the ISM atlas (VPLs).
//
// Interleaved sampling (Segovia et al. 2006): with interleave n > 1, pixel (x, y) is lit by the
// VPLs j = s, s + n^2, ... of its subset s = (x mod n) + n (y mod n), scaled by n^2; dir_merge.comp
// then averages the indirect light over n x n neighbours. The dispatch is laid out as n x n
// sub-buffers (invocation block (sx, sy) shades the pixels of subset (sx, sy)), so neighbouring
// invocations read the same VPLs.
//
// Output per pixel (4 vec4): direct L_rv + emission (w: virtual coverage), direct L_r,
// indirect L_rv, indirect L_r; the w of the last three hold the k_d texture factor, which
// dir_merge.comp applies to the merged indirect light (the indirect light is shaded with the
// material's own k_d, the direct light with the textured one; dir_cpu.cpp's MapShader::shade).
#include "dir_common.glsl"
#include "phong.glsl"

layout(local_size_x = 8, local_size_y = 8) in;

struct Material {
  vec4 kd_ks;        // k_d, k_s
  vec4 emission_n;   // emission, Phong exponent n
  vec4 texture;      // x, y, z: its base-colour, emission and metallic-roughness textures' headers in
                     // texture_words (bits; 0xffffffff: none); w: roughness factor
  vec4 pbr;          // MetallicRoughness (mr_scene.h): base colour factor, metallic factor
  vec4 normal_map;   // x: its normal texture's header (bits; 0xffffffff: none), y: its scale
};
struct Light {
  vec4 position_kind;      // w: 0 point, 1 spot, 2 directional, 3 directional through its emitter VPL (bits)
  vec4 direction_real;     // unit; w: r(light)
  vec4 intensity_inner;    // w: cos_inner
  vec4 outer_views;        // x: cos_outer, y: first view (bits), z: view count (bits)
};
struct ShadowView {
  mat4 world_to_clip;
  vec4 eye;
  vec4 texel_size;
};

// positions, then normals, then texture coordinates (GBufferVk::packed_bytes)
layout(std430, set = 0, binding = 0) readonly buffer GBuffer { vec4 gbuffer[]; };
layout(std430, set = 0, binding = 1) readonly buffer Materials { Material materials[]; };
layout(std430, set = 0, binding = 2) readonly buffer Lights { Light lights[]; };
layout(std430, set = 0, binding = 3) readonly buffer Views { ShadowView views[]; };
layout(std430, set = 0, binding = 4) readonly buffer ShadowAtlas { float shadow_atlas[]; };
layout(std430, set = 0, binding = 5) readonly buffer Vpls { Vpl vpls[]; };
layout(std430, set = 0, binding = 6) readonly buffer IsmAtlas { float ism_atlas[]; };
layout(std430, set = 0, binding = 7) writeonly buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 8) readonly buffer Textures { uint texture_words[]; };
#include "dir_texture.glsl"
#include "normal_map.glsl"

layout(push_constant) uniform Params {
  uint width;
  uint height;
  uint light_count;
  uint vpl_count;
  int shadow_tile;
  int shadow_columns;
  int shadow_rows;
  int ism_tile;
  float min_distance;
  uint flags;  // bit 0 direct, bit 1 indirect, bit 2 write L_rv, bit 3 write L_r
  uint interleave;
  uint emitter_count;  // the last emitter_count VPLs are emitters (vpl.h)
  vec4 camera_centre;
  vec4 environment;     // w: DirOptions::real_depth_noise_sigmas
  vec4 virtual_bounds;  // IsmPointPools::virtual_bounds
  vec4 scene_bounds;    // IsmPointPools::scene_bounds
} params;

// surface_phong() (mr_scene.h): the material's Phong parameters where its metallic-roughness
// texture reads `mr` (G roughness, B metallic), through phong_from_metallic_roughness().
Material surface_material(Material m, vec3 mr) {
  if (floatBitsToUint(m.texture.z) == NO_TEXTURE) return m;
  const float metallic = clamp(m.pbr.w * mr.z, 0.0, 1.0), roughness = clamp(m.texture.w * mr.y, 0.0, 1.0);
  const vec3 base = m.pbr.xyz;
  m.kd_ks.xyz = base * (1.0 - metallic);
  m.kd_ks.w = 0.04 * (1.0 - metallic) + dot(base, vec3(0.2126, 0.7152, 0.0722)) * metallic;
  const float alpha = max(1e-3, roughness * roughness);
  m.emission_n.w = clamp(2.0 / (alpha * alpha) - 2.0, 1.0, 10000.0);
  return m;
}

// phong_brdf() (core/phong.h, core/shaders/phong.glsl) of a packed material.
vec3 phong(Material m, vec3 n, vec3 wi, vec3 wo) { return phong_brdf(m.kd_ks.xyz, m.kd_ks.w, m.emission_n.w, n, wi, wo); }

// shadow_visibility() (shadow_maps.h).
float shadow_visibility(Light light, int layer, vec3 point, vec3 normal, float surface_tolerance) {
  const uint first = floatBitsToUint(light.outer_views.y), count = floatBitsToUint(light.outer_views.z);
  if (count == 0u) return 1.0;
  const int rows = max(params.shadow_rows, 1);
  const uint layer_base = uint(layer * rows * params.shadow_columns);  // pack_views (dir_vk.cpp)
  const vec4 any_eye = views[layer_base + first].eye;
  const bool positional = any_eye.w > 0.5;
  const vec3 towards_light = positional ? any_eye.xyz - point : any_eye.xyz;
  uint index = first;
  if (count == 6u) {
    const vec3 d = point - any_eye.xyz, a = abs(d);
    const int axis = a.x >= a.y && a.x >= a.z ? 0 : (a.y >= a.z ? 1 : 2);
    index += uint(2 * axis + (d[axis] < 0.0 ? 1 : 0));
  }
  const ShadowView view = views[layer_base + index];
  const float texel = positional ? view.texel_size.x * length(towards_light) : view.texel_size.x;
  const vec3 facing = dot(normal, towards_light) < 0.0 ? -normal : normal;
  const float cos_incidence = max(abs(dot(normal, normalize(towards_light))), 0.2);
  const float tolerance = texel + surface_tolerance / cos_incidence;
  const vec3 receiver = point + 0.5 * texel * facing;
  const vec4 clip = view.world_to_clip * vec4(receiver, 1.0);
  if (clip.w <= 0.0) return 1.0;
  const vec2 ndc = clip.xy / clip.w;
  if (abs(ndc.x) > 1.0 || abs(ndc.y) > 1.0) return 1.0;
  const int tile = params.shadow_tile;
  const ivec2 texel_xy = clamp(ivec2(floor((ndc * 0.5 + 0.5) * float(tile))), ivec2(0), ivec2(tile - 1));
  const ivec2 origin = ivec2((int(index) % params.shadow_columns) * tile, (layer * rows + int(index) / params.shadow_columns) * tile);
  const float stored = shadow_atlas[(origin.y + texel_xy.y) * params.shadow_columns * tile + origin.x + texel_xy.x];
  const float depth = positional ? length(receiver - view.eye.xyz) : -dot(receiver, view.eye.xyz);
  return depth <= stored + tolerance ? 1.0 : 0.0;
}

// IsmLookup::visible (ism.h); constant_bias: kIsmBias or kEmitterVirtualIsmBias.
float ism_visible(Projection projection, uint tile_offset, vec3 point, float constant_bias) {
  float distance;
  const vec3 dir = projection_local(projection, point, distance);
  vec2 texel;
  if (!(distance > 0.0) || !projection_texel(projection, dir, params.ism_tile, texel)) return 1.0;
  const int tile = params.ism_tile;
  const ivec2 xy = clamp(ivec2(floor(texel)), ivec2(0), ivec2(tile - 1));
  const float reach = distance - (constant_bias + distance * 2.0 * texel_angle(projection, tile));
  return reach <= ism_atlas[tile_offset + uint(xy.y * tile + xy.x)] ? 1.0 : 0.0;
}

// IsmLookup: V_r from the VPL's real tile (its hemisphere), V_v from its (focused) virtual tile.
vec2 ism_visibility(uint index, Vpl vpl, vec3 point) {
  const uint texels = uint(params.ism_tile * params.ism_tile);
  const float real = ism_visible(real_tile(vpl, params.scene_bounds), index * texels, point, 0.02);
  if (real == 0.0) return vec2(0.0);
  return vec2(real, ism_visible(virtual_tile(vpl, params.virtual_bounds, params.scene_bounds),
                                (params.vpl_count + index) * texels, point, is_emitter(vpl) ? 0.002 : 0.02));
}

void main() {
  const uint interleave = params.interleave;
  const uvec2 sub_size = (uvec2(params.width, params.height) + interleave - 1u) / interleave;
  const uvec2 id = gl_GlobalInvocationID.xy;
  const uvec2 pixel = (id % sub_size) * interleave + id / sub_size;
  if (id.x >= sub_size.x * interleave || id.y >= sub_size.y * interleave || pixel.x >= params.width || pixel.y >= params.height) return;
  const uint pixels = params.width * params.height;
  const uint i = pixel.y * params.width + pixel.x;
  const vec4 position = gbuffer[i];
  if (position.w == 0.0) {
    radiance[4u * i] = vec4(params.environment.xyz, 0.0);
    radiance[4u * i + 1u] = vec4(params.environment.xyz, 1.0);
    radiance[4u * i + 2u] = vec4(0.0, 0.0, 0.0, 1.0);
    radiance[4u * i + 3u] = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  const vec4 normal_material = gbuffer[pixels + i];
  const vec3 point = position.xyz;
  const float real_pixel = position.w > 0.0 ? 1.0 : 0.0;  // r(p)
  const vec3 wo = normalize(params.camera_centre.xyz - point);
  // real_surface_tolerance() (shadow_maps.h); params.environment.w: DirOptions::real_depth_noise_sigmas.
  const float z = length(params.camera_centre.xyz - point) - 0.4;
  const float real_tolerance = real_pixel * params.environment.w * (0.0012 + 0.0019 * z * z);
  // texture_factors() (gbuffer.h): the textures at the pixel's coordinates and footprint.
  const vec4 t = gbuffer[2u * pixels + i];
  const Material material = materials[uint(normal_material.w)];
  const Material own = surface_material(material, material_texture(floatBitsToUint(material.texture.z), t));
  // shading_normals() (gbuffer.h): the G-buffer's normal bent by the material's normal texture.
  vec3 n = normal_material.xyz;
  const uint normal_header = floatBitsToUint(material.normal_map.x);
  vec3 tangent;
  float handedness;
  if (normal_header != NO_TEXTURE && decode_tangent(t.w, n, tangent, handedness))
    n = mapped_normal(n, tangent, handedness, material_texture(normal_header, t), material.normal_map.y);
  const vec3 kd_texture = material_texture(floatBitsToUint(own.texture.x), t);
  Material m = own;  // textured: for the direct light
  m.kd_ks.xyz *= kd_texture;
  m.emission_n.xyz *= material_texture(floatBitsToUint(own.texture.y), t);
  vec3 rv = m.emission_n.xyz;
  vec3 r = real_pixel * m.emission_n.xyz;
  const bool want_rv = (params.flags & 4u) != 0u, want_r = (params.flags & 8u) != 0u;

  if ((params.flags & 1u) != 0u) {
    for (uint l = 0u; l < params.light_count; ++l) {
      const Light light = lights[l];
      const uint kind = floatBitsToUint(light.position_kind.w);
      if (kind == 3u) continue;  // its emitter VPL lights the point (vpl.h)
      vec3 wi, irradiance;
      if (kind == 2u) {
        wi = light.direction_real.xyz;
        irradiance = light.intensity_inner.xyz;
      } else {
        const vec3 to_light = light.position_kind.xyz - point;
        const float d2 = dot(to_light, to_light);
        if (!(d2 > 0.0)) continue;
        wi = to_light / sqrt(d2);
        float falloff = 1.0;
        if (kind == 1u) {
          const float c = dot(light.direction_real.xyz, -wi);
          const float inner = light.intensity_inner.w, outer = light.outer_views.x;
          const float x = clamp((c - outer) / (inner - outer), 0.0, 1.0);
          falloff = c <= outer ? 0.0 : (c >= inner ? 1.0 : x * x * (3.0 - 2.0 * x));
        }
        if (falloff <= 0.0) continue;
        irradiance = light.intensity_inner.xyz * (falloff / d2);
      }
      const float cos_i = dot(wi, n);
      if (cos_i <= 0.0) continue;
      const vec3 contribution = phong(m, n, wi, wo) * irradiance * cos_i;
      const float v_r = shadow_visibility(light, 0, point, n, real_tolerance);
      if (v_r == 0.0) continue;
      if (want_rv) rv += contribution * shadow_visibility(light, 1, point, n, 0.0);
      r += contribution * (light.direction_real.w * real_pixel);
    }
    // Emitter VPLs (vpl.h), the last emitter_count VPLs: every pixel sees all of them.
    for (uint j = params.vpl_count - params.emitter_count; j < params.vpl_count; ++j) {
      const Vpl vpl = vpls[j];
      const uint flags = floatBitsToUint(vpl.normal_flags.w);
      const bool in_rv = want_rv && (flags & 2u) != 0u;
      const bool in_r = want_r && (flags & 4u) != 0u && real_pixel > 0.0;
      const float cos_x = dot(vpl.incident.xyz, n);
      if ((!in_rv && !in_r) || cos_x <= 0.0) continue;
      const vec3 contribution = vpl.flux.xyz * phong(m, n, vpl.incident.xyz, wo) * cos_x;
      const vec2 seen = ism_visibility(j, vpl, point);
      if (seen.x == 0.0) continue;
      if (in_rv) rv += contribution * seen.y;
      if (in_r) r += contribution;
    }
  }

  vec3 indirect_rv = vec3(0.0), indirect_r = vec3(0.0);
  if ((params.flags & 2u) != 0u) {
    const float min_d2 = params.min_distance * params.min_distance;
    const uint subset = (pixel.x % interleave) + interleave * (pixel.y % interleave);
    for (uint j = subset; j < params.vpl_count - params.emitter_count; j += interleave * interleave) {
      const Vpl vpl = vpls[j];
      const uint flags = floatBitsToUint(vpl.normal_flags.w);
      const bool in_rv = want_rv && (flags & 2u) != 0u;
      const bool in_r = want_r && (flags & 4u) != 0u && real_pixel > 0.0;
      if (!in_rv && !in_r) continue;
      const vec3 to_vpl = vpl.position_material.xyz - point;
      const float d2 = dot(to_vpl, to_vpl);
      if (!(d2 > 0.0)) continue;
      const vec3 wi = to_vpl / sqrt(d2);
      const float cos_x = dot(wi, n), cos_y = -dot(wi, vpl.normal_flags.xyz);
      if (cos_x <= 0.0 || cos_y <= 0.0) continue;
      // vpl_phong() (vpl.h).
      Material mv = surface_material(materials[floatBitsToUint(vpl.position_material.w)],
                                     vec3(1.0, vpl.incident.w, vpl.flux.w));
      mv.kd_ks.xyz *= vpl.kd_texture.xyz;
      const vec3 contribution = vpl.flux.xyz * phong(mv, vpl.normal_flags.xyz, vpl.incident.xyz, -wi) *
                                phong(own, n, wi, wo) * (cos_x * cos_y / max(d2, min_d2));
      const vec2 seen = ism_visibility(j, vpl, point);
      if (seen.x == 0.0) continue;
      if (in_rv) indirect_rv += contribution * seen.y;
      if (in_r) indirect_r += contribution;
    }
  }
  const float scale = float(interleave * interleave);
  radiance[4u * i] = vec4(rv, 1.0 - real_pixel);
  radiance[4u * i + 1u] = vec4(r, kd_texture.x);
  radiance[4u * i + 2u] = vec4(indirect_rv * scale, kd_texture.y);
  radiance[4u * i + 3u] = vec4(indirect_r * scale, kd_texture.z);
}
