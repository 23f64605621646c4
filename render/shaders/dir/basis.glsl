// orthonormal_basis() (phong_brdf.h), Duff et al. 2017: shared by the DIR shaders.
#ifndef RELIGHT_BASIS_GLSL
#define RELIGHT_BASIS_GLSL
void orthonormal_basis(vec3 n, out vec3 t, out vec3 b) {
  const float s = n.z >= 0.0 ? 1.0 : -1.0;
  const float a = -1.0 / (s + n.z);
  const float c = n.x * n.y * a;
  t = vec3(1.0 + s * n.x * n.x * a, s * c, -s * n.x);
  b = vec3(c, s + n.y * n.y * a, -n.y);
}

#endif
