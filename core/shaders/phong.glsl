// GLSL twin of core/include/relight/core/phong.h, the normalised Phong model
//   f(wi, wo) = k_d / pi + k_s (n + 2) / (2 pi) max(0, r(wi) . wo)^n,   r(wi) = 2 (n.wi) n - wi
// Every shader that evaluates the model includes this file (relight_embed_shaders adds
// core/shaders to the include path); tests/core/vk/phong_twin_test.cpp checks it against the C++.
#ifndef RELIGHT_PHONG_GLSL
#define RELIGHT_PHONG_GLSL

const float kPhongInvPi = 0.31830988618379067;
const float kPhongMinLobeCosine = 1e-12;  // kPhongMinLobeCosine (phong.h)

float phong_lobe_normalisation(float n) { return (n + 2.0) * (0.5 * kPhongInvPi); }

float phong_lobe(float n, float cos_alpha) { return cos_alpha > kPhongMinLobeCosine ? pow(cos_alpha, n) : 0.0; }

float phong_specular(float ks, float n, float cos_alpha) {
  return ks * phong_lobe_normalisation(n) * phong_lobe(n, cos_alpha);
}

vec3 phong_reflect(vec3 direction, vec3 normal) { return 2.0 * dot(normal, direction) * normal - direction; }

vec3 phong_brdf(vec3 kd, float ks, float n, vec3 normal, vec3 wi, vec3 wo) {
  if (dot(normal, wi) <= 0.0 || dot(normal, wo) <= 0.0) return vec3(0.0);
  const float specular = ks > 0.0 ? phong_specular(ks, n, dot(phong_reflect(wi, normal), wo)) : 0.0;
  return kd * kPhongInvPi + vec3(specular);
}

#endif
