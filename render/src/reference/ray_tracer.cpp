#include "relight/render/reference/ray_tracer.h"

#include <embree3/rtcore.h>

#include <array>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "relight/core/error.h"
#include "relight/render/scene/normal_map.h"

namespace relight::render {
namespace {

struct DeviceDeleter {
  void operator()(RTCDevice device) const { rtcReleaseDevice(device); }
};
struct SceneDeleter {
  void operator()(RTCScene scene) const { rtcReleaseScene(scene); }
};
using DeviceHandle = std::unique_ptr<RTCDeviceTy, DeviceDeleter>;
using SceneHandle = std::unique_ptr<RTCSceneTy, SceneDeleter>;

const char* describe(RTCError error) {
  switch (error) {
    case RTC_ERROR_OUT_OF_MEMORY: return "out of memory";
    case RTC_ERROR_INVALID_ARGUMENT: return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_UNSUPPORTED_CPU: return "unsupported CPU";
    default: return "unknown error";
  }
}

void check(RTCDevice device, const char* what) {
  const RTCError error = rtcGetDeviceError(device);
  if (error != RTC_ERROR_NONE) throw Error(std::string("Embree: ") + what + " failed: " + describe(error));
}

/// One acceleration structure and, per Embree geometry id, the mesh it came from.
struct LayerScene {
  SceneHandle scene;
  std::vector<const TriangleMesh*> meshes;
};

void attach_mesh(RTCDevice device, LayerScene& layer, const TriangleMesh& mesh) {
  if (mesh.triangles.empty()) return;
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  check(device, "creating a triangle geometry");
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                               3 * sizeof(float), mesh.positions.size()));
  auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), mesh.triangles.size()));
  if (vertices == nullptr || indices == nullptr) {
    rtcReleaseGeometry(geometry);
    throw Error("Embree: out of memory for mesh '" + mesh.name + "'");
  }
  for (std::size_t i = 0; i < mesh.positions.size(); ++i)
    for (int c = 0; c < 3; ++c) vertices[3 * i + static_cast<std::size_t>(c)] = mesh.positions[i][c];
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i)
    for (int c = 0; c < 3; ++c) indices[3 * i + static_cast<std::size_t>(c)] = mesh.triangles[i][static_cast<std::size_t>(c)];
  rtcCommitGeometry(geometry);
  const unsigned id = rtcAttachGeometry(layer.scene.get(), geometry);
  rtcReleaseGeometry(geometry);  // the scene holds its own reference
  check(device, "adding a mesh");
  if (id != layer.meshes.size()) throw LogicError("Embree geometry ids are expected to be sequential");
  layer.meshes.push_back(&mesh);
}

RTCRay make_ray(const Eigen::Vector3f& origin, const Eigen::Vector3f& direction, float t_max) {
  RTCRay ray{};
  ray.org_x = origin.x();
  ray.org_y = origin.y();
  ray.org_z = origin.z();
  ray.dir_x = direction.x();
  ray.dir_y = direction.y();
  ray.dir_z = direction.z();
  ray.tnear = 0.f;
  ray.tfar = t_max;
  ray.mask = 0xffffffffu;
  return ray;
}

/// The hit's texture coordinates (barycentric u, v) and their gradient along the triangle: with
/// edges e1, e2 and coordinate differences t1, t2, a point p0 + a e1 + b e2 has coordinates
/// uv0 + a t1 + b t2, and (a, b) follows from the edges' Gram matrix.
void add_texcoords(const TriangleMesh& mesh, const std::array<std::uint32_t, 3>& triangle, float u, float v,
                   SurfaceHit& hit) {
  const Eigen::Vector2f& uv0 = mesh.texcoords[triangle[0]];
  const Eigen::Vector2f& uv1 = mesh.texcoords[triangle[1]];
  const Eigen::Vector2f& uv2 = mesh.texcoords[triangle[2]];
  hit.has_texcoord = true;
  hit.texcoord = (1.f - u - v) * uv0 + u * uv1 + v * uv2;
  const Eigen::Vector3f e1 = mesh.positions[triangle[1]] - mesh.positions[triangle[0]];
  const Eigen::Vector3f e2 = mesh.positions[triangle[2]] - mesh.positions[triangle[0]];
  Eigen::Matrix2f gram;
  gram << e1.dot(e1), e1.dot(e2), e1.dot(e2), e2.dot(e2);
  const float determinant = gram.determinant();
  if (!(std::abs(determinant) > 0.f)) return;
  Eigen::Matrix<float, 2, 3> edges;
  edges.row(0) = e1.transpose();
  edges.row(1) = e2.transpose();
  Eigen::Matrix2f differences;
  differences.col(0) = uv1 - uv0;
  differences.col(1) = uv2 - uv0;
  hit.texcoord_gradient = differences * gram.inverse() * edges;
}

/// texture_at() at a hit: at its coordinates, or the texture's mean where it has none.
Eigen::Vector3f texture_at_hit(const std::shared_ptr<const Texture>& texture, const SurfaceHit& hit, float lod = 0.f) {
  return texture_at(texture.get(), hit.has_texcoord ? &hit.texcoord : nullptr, lod);
}

}  // namespace

Eigen::Vector3f base_color_at(const MrScene& scene, const SurfaceHit& hit, float lod) {
  return texture_at_hit(scene.materials[hit.material].base_color, hit, lod);
}

Eigen::Vector3f emission_at(const MrScene& scene, const SurfaceHit& hit) {
  const PhongMaterial& material = scene.materials[hit.material];
  return material.emission.cwiseProduct(texture_at_hit(material.emission_texture, hit));
}

Eigen::Vector3f metallic_roughness_at(const MrScene& scene, const SurfaceHit& hit, float lod) {
  return texture_at_hit(scene.materials[hit.material].metallic_roughness_texture, hit, lod);
}

Phong phong_at(const MrScene& scene, const SurfaceHit& hit, float lod) {
  return with_kd_factor(surface_phong(scene.materials[hit.material], metallic_roughness_at(scene, hit, lod)),
                        base_color_at(scene, hit, lod));
}

struct RayTracer::Impl {
  MrScene scene;  // owns the meshes the layers point into
  DeviceHandle device;
  LayerScene real, virtual_objects;

  [[nodiscard]] const LayerScene& layer(Layer which) const { return which == Layer::Real ? real : virtual_objects; }
};

RayTracer::RayTracer(MrScene scene, Build build) : impl_(std::make_unique<Impl>()) {
  scene.validate();
  impl_->scene = std::move(scene);
  impl_->device.reset(rtcNewDevice(nullptr));
  if (!impl_->device) throw Error("Embree: cannot create a device (unsupported CPU or out of memory)");
  RTCDevice device = impl_->device.get();
  for (LayerScene* layer : {&impl_->real, &impl_->virtual_objects}) {
    layer->scene.reset(rtcNewScene(device));
    check(device, "creating a scene");
    rtcSetSceneBuildQuality(layer->scene.get(), build == Build::High ? RTC_BUILD_QUALITY_HIGH : RTC_BUILD_QUALITY_LOW);
  }
  for (const TriangleMesh& mesh : impl_->scene.meshes)
    attach_mesh(device, mesh.real ? impl_->real : impl_->virtual_objects, mesh);
  for (LayerScene* layer : {&impl_->real, &impl_->virtual_objects}) {
    rtcCommitScene(layer->scene.get());
    check(device, "building the acceleration structure");
  }
}

RayTracer::~RayTracer() = default;

const MrScene& RayTracer::scene() const { return impl_->scene; }

bool RayTracer::has_virtual_geometry() const { return !impl_->virtual_objects.meshes.empty(); }

std::optional<SurfaceHit> RayTracer::intersect(Layer which, const Eigen::Vector3f& origin,
                                               const Eigen::Vector3f& direction, float t_max) const {
  const LayerScene& layer = impl_->layer(which);
  if (layer.meshes.empty()) return std::nullopt;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit query{};
  query.ray = make_ray(origin, direction, t_max);
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(layer.scene.get(), &context, &query);
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return std::nullopt;

  const TriangleMesh& mesh = *layer.meshes[query.hit.geomID];
  const auto& triangle = mesh.triangles[query.hit.primID];
  SurfaceHit hit;
  hit.t = query.ray.tfar;
  hit.point = origin + hit.t * direction;
  hit.geometric_normal = Eigen::Vector3f(query.hit.Ng_x, query.hit.Ng_y, query.hit.Ng_z).normalized();
  if (mesh.normals.empty()) {
    hit.interpolated_normal = hit.geometric_normal;
  } else {
    const float u = query.hit.u, v = query.hit.v;
    const Eigen::Vector3f n = (1.f - u - v) * mesh.normals[triangle[0]] + u * mesh.normals[triangle[1]] +
                              v * mesh.normals[triangle[2]];
    const float length = n.norm();
    hit.interpolated_normal = length > 0.f ? Eigen::Vector3f(n / length) : hit.geometric_normal;
  }
  hit.shading_normal = hit.interpolated_normal;
  hit.material = mesh.triangle_material[query.hit.primID];
  hit.real = mesh.real;
  if (!mesh.texcoords.empty()) {
    add_texcoords(mesh, triangle, query.hit.u, query.hit.v, hit);
    const PhongMaterial& material = impl_->scene.materials[hit.material];
    if (material.normal_texture) {
      if (const std::optional<TangentFrame> frame = tangent_frame(hit.texcoord_gradient, hit.interpolated_normal))
        hit.shading_normal = mapped_normal(hit.interpolated_normal, *frame,
                                           texture_at_hit(material.normal_texture, hit), material.normal_scale);
    }
  }
  return hit;
}

bool RayTracer::occluded(Layer which, const Eigen::Vector3f& origin, const Eigen::Vector3f& direction,
                         float t_max) const {
  const LayerScene& layer = impl_->layer(which);
  if (layer.meshes.empty()) return false;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray = make_ray(origin, direction, t_max);
  rtcOccluded1(layer.scene.get(), &context, &ray);
  return ray.tfar < 0.f;
}

}  // namespace relight::render
