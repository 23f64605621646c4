// Material textures in a storage buffer: the GLSL twin of Texture::sample (render/scene/
// texture.h), reading the words pack_textures() (dir_vk.cpp) writes. The includer declares
//   readonly buffer Textures { uint texture_words[]; };
// A texture starts at word `header`: levels, wrap u, wrap v, the longer side of level 0, its
// UvTransform (linear row by row, offset; floats as bits), its stretch(), 0; then per level
// (absolute word index of its first texel, width, height, encoding: 0 sRGB, 1 linear), texels
// r | g << 8 | b << 16.

float srgb_to_linear(uint value) {
  const float c = float(value) / 255.0;
  return c <= 0.04045 ? c / 12.92 : pow((c + 0.055) / 1.055, 2.4);
}

// Texture::decode.
vec3 texel_linear(uint word, uint encoding) {
  if (encoding == 1u) return vec3(float(word & 0xffu), float((word >> 8) & 0xffu), float((word >> 16) & 0xffu)) / 255.0;
  return vec3(srgb_to_linear(word & 0xffu), srgb_to_linear((word >> 8) & 0xffu), srgb_to_linear((word >> 16) & 0xffu));
}

// TextureWrap: 0 repeat, 1 clamp to edge, 2 mirrored repeat.
int wrapped_texel(int i, int size, uint wrap) {
  if (wrap == 1u) return clamp(i, 0, size - 1);
  if (wrap == 2u) {
    const int period = 2 * size;
    const int m = ((i % period) + period) % period;
    return m < size ? m : period - 1 - m;
  }
  return ((i % size) + size) % size;
}

const uint TEXTURE_HEADER = 12u;     // kTextureHeaderWords (dir_vk.cpp)
const uint NO_TEXTURE = 0xffffffffu;  // kNoTexture (dir_vk.cpp): a material slot without a texture

// UvTransform::apply.
vec2 texture_transform(uint header, vec2 uv) {
  const vec2 row0 = vec2(uintBitsToFloat(texture_words[header + 4u]), uintBitsToFloat(texture_words[header + 5u]));
  const vec2 row1 = vec2(uintBitsToFloat(texture_words[header + 6u]), uintBitsToFloat(texture_words[header + 7u]));
  const vec2 offset = vec2(uintBitsToFloat(texture_words[header + 8u]), uintBitsToFloat(texture_words[header + 9u]));
  return vec2(dot(row0, uv), dot(row1, uv)) + offset;
}

vec3 texture_bilinear(uint header, uint level, vec2 uv) {
  const uint base = header + TEXTURE_HEADER + 4u * level;
  const uint first = texture_words[base];
  const int w = int(texture_words[base + 1u]), h = int(texture_words[base + 2u]);
  const uint encoding = texture_words[base + 3u];
  const uint wrap_u = texture_words[header + 1u], wrap_v = texture_words[header + 2u];
  const vec2 xy = uv * vec2(w, h) - 0.5;
  const vec2 corner = floor(xy);
  const vec2 f = xy - corner;
  // Far outside [0, 1] only the period matters (Texture::bilinear's fmod).
  const int x0 = int(mod(corner.x, 2.0 * float(w) * 1024.0)), y0 = int(mod(corner.y, 2.0 * float(h) * 1024.0));
  const int xa = wrapped_texel(x0, w, wrap_u), xb = wrapped_texel(x0 + 1, w, wrap_u);
  const int ya = wrapped_texel(y0, h, wrap_v), yb = wrapped_texel(y0 + 1, h, wrap_v);
  const vec3 c00 = texel_linear(texture_words[first + uint(ya * w + xa)], encoding);
  const vec3 c10 = texel_linear(texture_words[first + uint(ya * w + xb)], encoding);
  const vec3 c01 = texel_linear(texture_words[first + uint(yb * w + xa)], encoding);
  const vec3 c11 = texel_linear(texture_words[first + uint(yb * w + xb)], encoding);
  return (1.0 - f.y) * ((1.0 - f.x) * c00 + f.x * c10) + f.y * ((1.0 - f.x) * c01 + f.x * c11);
}

vec3 texture_mean(uint header) {
  const uint top = header + TEXTURE_HEADER + 4u * (texture_words[header] - 1u);
  return texel_linear(texture_words[texture_words[top]], texture_words[top + 3u]);
}

// Texture::level_of_detail.
float texture_level(uint header, float footprint) {
  const float texels = footprint * uintBitsToFloat(texture_words[header + 10u]) * float(texture_words[header + 3u]);
  if (!(texels > 1.0)) return 0.0;
  return min(log2(texels), float(texture_words[header] - 1u));
}

vec3 texture_sample(uint header, vec2 coordinates, float lod) {
  const vec2 uv = texture_transform(header, coordinates);
  const uint levels = texture_words[header];
  const float level = clamp(lod, 0.0, float(levels - 1u));
  const uint l0 = uint(level);
  const float f = level - float(l0);
  const vec3 near = texture_bilinear(header, l0, uv);
  if (f == 0.0 || l0 + 1u >= levels) return near;
  return (1.0 - f) * near + f * texture_bilinear(header, l0 + 1u, uv);
}

// texture_factors() (gbuffer.h) at one pixel: 1 without a texture (header 0xffffffff), the
// texture's mean where the G-buffer's footprint (texcoord.z) marks no coordinates.
vec3 material_texture(uint header, vec4 texcoord) {
  if (header == NO_TEXTURE) return vec3(1.0);
  return texcoord.z > 0.0 ? texture_sample(header, texcoord.xy, texture_level(header, texcoord.z)) : texture_mean(header);
}
