#include "relight/render/scene/normal_map.h"

#include <Eigen/Geometry>

#include <cmath>

#include "relight/render/scene/phong_brdf.h"

namespace relight::render {

std::optional<TangentFrame> tangent_frame(const Eigen::Vector3f& dp_du, const Eigen::Vector3f& dp_dv,
                                          const Eigen::Vector3f& normal) {
  const Eigen::Vector3f along = dp_du - normal * normal.dot(dp_du);
  const float length = along.norm();
  if (!(length > 1e-12f) || !std::isfinite(length)) return std::nullopt;
  TangentFrame frame;
  frame.tangent = along / length;
  // Unmirrored (u right, v down the image): N x T points along -dP/dv, the map's +y.
  frame.handedness = normal.cross(frame.tangent).dot(dp_dv) <= 0.f ? 1.f : -1.f;
  return frame;
}

std::optional<TangentFrame> tangent_frame(const Eigen::Matrix<float, 2, 3>& texcoord_gradient,
                                          const Eigen::Vector3f& normal) {
  // The gradient G maps a step on the plane to (du, dv); [dP/du dP/dv] = G^T (G G^T)^-1 is the
  // step on the plane that changes u (or v) alone by one.
  const Eigen::Matrix2f gram = texcoord_gradient * texcoord_gradient.transpose();
  const float determinant = gram.determinant();
  if (!(std::abs(determinant) > 0.f) || !std::isfinite(determinant)) return std::nullopt;
  const Eigen::Matrix<float, 3, 2> inverse = texcoord_gradient.transpose() * gram.inverse();
  return tangent_frame(inverse.col(0), inverse.col(1), normal);
}

TangentFrame flipped(const TangentFrame& frame) { return {-frame.tangent, -frame.handedness}; }

Eigen::Vector3f mapped_normal(const Eigen::Vector3f& normal, const TangentFrame& frame, const Eigen::Vector3f& texel,
                              float scale) {
  const Eigen::Vector3f m = 2.f * texel - Eigen::Vector3f::Ones();
  const Eigen::Vector3f bitangent = frame.handedness * normal.cross(frame.tangent);
  const Eigen::Vector3f bent = scale * m.x() * frame.tangent + scale * m.y() * bitangent + m.z() * normal;
  const float length = bent.norm();
  return length > 1e-6f && std::isfinite(length) ? Eigen::Vector3f(bent / length) : normal;
}

float encode_tangent(const std::optional<TangentFrame>& frame, const Eigen::Vector3f& normal) {
  if (!frame) return 0.f;
  Eigen::Vector3f t, b;
  orthonormal_basis(normal, t, b);
  const float angle = std::atan2(frame->tangent.dot(b), frame->tangent.dot(t));
  return angle + (frame->handedness > 0.f ? 4.f : 12.f);
}

std::optional<TangentFrame> decode_tangent(float code, const Eigen::Vector3f& normal) {
  if (!(code > 0.f)) return std::nullopt;
  const bool right_handed = code < 8.f;
  const float angle = code - (right_handed ? 4.f : 12.f);
  Eigen::Vector3f t, b;
  orthonormal_basis(normal, t, b);
  return TangentFrame{std::cos(angle) * t + std::sin(angle) * b, right_handed ? 1.f : -1.f};
}

}  // namespace relight::render
