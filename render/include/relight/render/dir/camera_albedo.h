#pragma once
// The camera's own albedo for the real surfaces it sees (differential rendering after Debevec
// 1998): the renderer shades real surfaces with their material cluster's k_d (brdf::Materials),
// and a cluster's k_d is the mean of many pixels, so TM(L_r) misses the camera's colours by the
// spread inside the cluster (the synthetic table shares a cluster with the floor: L_r came out
// (0.79, 0.41, 0.14) where the camera shows (0.58, 0.43, 0.30)). Because the composite adds
// ΔL = TM(L_rv) − TM(L_r), that error scales every shadow and reflection of a virtual object:
// in a deep virtual shadow the camera colour minus that L_r left a saturated blue.
//
// modulate_camera_albedo() replaces, on real G-buffer pixels of a purely diffuse material (k_s
// = 0, where L = k_d/π · irradiance exactly), the cluster's k_d by the pixel's own estimate
// k_d(x, y) (brdf/ diffuse estimation, eq. 4.13; smoothed, see kAlbedoSmoothingRadius), scaling
// all four radiance parts per channel by k_d(x, y) / k_d(cluster). It runs after the interleaved merge, so the merged indirect light
// (an irradiance times the cluster's constant k_d) is modulated, not blurred, by the texture.
// Pixels where the estimate is invalid, glossy materials, virtual surfaces and channels where
// the cluster's k_d is below kMinClusterAlbedo keep the cluster's shading.
//
// Reads: GBuffer (same pixel grid as the camera image), the MrScene's materials, the per-pixel
// k_d image and its validity mask. Writes: DifferentialImages, in place.
#include "relight/core/image.h"
#include "relight/render/dir/gbuffer.h"
#include "relight/render/scene/mr_scene.h"
#include "relight/render/differential_images.h"

namespace relight::render {

inline constexpr float kMinClusterAlbedo = 0.01f;
/// The per-pixel estimate is averaged over the (2 r + 1)² pixels around it that share its
/// material and are modulated themselves: k_d(x, y) = I / irradiance(n) inherits the noise of
/// the estimated normal n, which a virtual shadow would otherwise show as coloured speckles
/// (measured on the real TUM desk).
inline constexpr int kAlbedoSmoothingRadius = 2;

/// Throws relight::Error when the images' sizes differ.
void modulate_camera_albedo(DifferentialImages& images, const GBuffer& gbuffer, const MrScene& scene,
                            const RadianceImage& albedo, const Mask& valid);

}  // namespace relight::render
