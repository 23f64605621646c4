// Shared between C++ (importance_sampling_*.cpp) and GLSL (shaders/importance_*.comp), so the
// push-constant and output layouts cannot drift apart. Plain C preprocessor only.
#ifndef RELIGHT_LIGHTS_IMPORTANCE_SHARED_H
#define RELIGHT_LIGHTS_IMPORTANCE_SHARED_H

#define RELIGHT_IMPORTANCE_PYRAMID_LOCAL_SIZE 16
#define RELIGHT_IMPORTANCE_WARP_LOCAL_SIZE 64
/// Pyramids of at most 2^15 x 2^15 pixels (16 levels).
#define RELIGHT_IMPORTANCE_MAX_LEVELS 16
/// The largest float below 1: warped coordinates stay in [0, 1).
#define RELIGHT_IMPORTANCE_ONE_MINUS_EPS 0.99999994

#ifdef __cplusplus
#include <cstdint>
namespace relight::gpu {
using uint = std::uint32_t;
#endif

/// Push constants of importance_pyramid.comp. level 0: importance of the probe pixels
/// (luminance x solid angle, zero-padded to size x size); level k > 0: 2x2 sums of level k - 1.
struct ImportancePyramidParams {
  uint width;          ///< probe image width
  uint height;         ///< probe image height
  uint level_size;     ///< edge of the level being written
  uint level;          ///< 0: from the probe; else from the level below
  uint source_offset;  ///< float index of the level below in the pyramid buffer
  uint target_offset;  ///< float index of the level being written
};

/// Push constants of importance_warp.comp (std430 scalars, 4 bytes each: 84 bytes).
struct ImportanceWarpParams {
  uint samples;       ///< N
  uint levels;        ///< L: the finest level is 2^L x 2^L, the top level (1x1) is level L
  uint width;         ///< probe image width
  uint height;        ///< probe image height
  uint projection;    ///< 0: equidistant fisheye, 1: equirectangular
  float inverse_samples;  ///< 1/N, rounded once on the host so both sides use the same value
  float offset_u;     ///< Cranley-Patterson rotation of the Hammersley set (from the seed)
  float offset_v;
  float cx;           ///< fisheye centre and focal length (pixels per radian) and max theta
  float cy;
  float focal;
  float max_theta;
  float probe_to_world[9];  ///< row-major
};

/// One warped sample as the shader writes it (48 bytes).
struct ImportanceSampleOut {
  float direction[3];  ///< world direction towards the light
  uint pixel;          ///< row * width + col of the probe pixel
  float power[3];      ///< RGB irradiance at normal incidence (light_set.h)
  float u;             ///< position inside the pixel, [0, 1)
  float v;
  float pad0;
  float pad1;
  float pad2;
};

#ifdef __cplusplus
static_assert(sizeof(ImportancePyramidParams) == 24);
static_assert(sizeof(ImportanceWarpParams) == 84);
static_assert(sizeof(ImportanceSampleOut) == 48);
}  // namespace relight::gpu
#endif

#endif  // RELIGHT_LIGHTS_IMPORTANCE_SHARED_H
