#pragma once
// Normal maps (glTF 2.0 `normalTexture`): the shading normal at a surface point, bent by the
// material's tangent-space normal texture.
//
// A texel t (linear, TextureEncoding::Linear) holds the tangent-space normal m = 2 t - 1, whose
// x and y the texture's `scale` multiplies; the world normal is normalize(m.x T + m.y B + m.z N)
// in the point's tangent frame (T, B = handedness (N x T), N), glTF's convention: T points along
// increasing u, and since glTF's v runs down the image while a normal map's +y points up it, B
// points along decreasing v for an unmirrored mapping (handedness +1; -1 where the mapping is
// mirrored).
//
// Departure from glTF: the tangent frame is the triangle's own, from its texture coordinates'
// gradient (RayTracer's hits) or their screen derivatives (the Vulkan G-buffer), orthogonalised
// against the interpolated normal - the "tangent-less" frame of Schüler (ShaderX5, 2006) and of
// Khronos' sample viewer without TANGENT - not MikkTSpace's per-vertex average, and a TANGENT
// attribute is not read. On a flat or finely tessellated surface the two agree; on a coarse
// curved one the tangent turns from triangle to triangle.
//
// The DIR G-buffer keeps the frame in one float (encode_tangent): the tangent's angle in the
// orthonormal basis of the pixel's normal (orthonormal_basis()) and the handedness in its offset,
// so that the GPU's G-buffer needs no fourth target (dir_shade.comp decodes it alike).
#include <Eigen/Core>
#include <optional>

namespace relight::render {

struct TangentFrame {
  Eigen::Vector3f tangent;  ///< unit, orthogonal to the normal it was made for
  float handedness = 1.f;   ///< +1 or -1: B = handedness (N x T)
};

/// The frame at a point with unit normal `normal` from dP/du and dP/dv (any length; along the
/// surface); nullopt where the coordinates do not span the surface.
[[nodiscard]] std::optional<TangentFrame> tangent_frame(const Eigen::Vector3f& dp_du, const Eigen::Vector3f& dp_dv,
                                                        const Eigen::Vector3f& normal);
/// The same from the coordinates' gradient on the triangle's plane (SurfaceHit::texcoord_gradient:
/// rows d u / d point and d v / d point).
[[nodiscard]] std::optional<TangentFrame> tangent_frame(const Eigen::Matrix<float, 2, 3>& texcoord_gradient,
                                                        const Eigen::Vector3f& normal);
/// The frame seen from the other side (the normal negated, as glTF's double-sided back faces):
/// tangent and handedness negated, so the mapped normal is the front's negated.
[[nodiscard]] TangentFrame flipped(const TangentFrame& frame);

/// The world normal bent by normal-texture texel `texel` (linear, [0, 1]^3) with the texture's
/// `scale`; `normal` where the result degenerates.
[[nodiscard]] Eigen::Vector3f mapped_normal(const Eigen::Vector3f& normal, const TangentFrame& frame,
                                            const Eigen::Vector3f& texel, float scale);

/// One float for the G-buffer: 0 without a frame; else the tangent's angle in
/// orthonormal_basis(normal) plus 4 (handedness +1) or 12 (-1).
[[nodiscard]] float encode_tangent(const std::optional<TangentFrame>& frame, const Eigen::Vector3f& normal);
[[nodiscard]] std::optional<TangentFrame> decode_tangent(float code, const Eigen::Vector3f& normal);

}  // namespace relight::render
