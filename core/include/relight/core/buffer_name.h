#pragma once
// A frame-graph buffer's name together with its C++ type. Every buffer of the pipeline has its
// name defined once, as a constant beside its type (core/buffers.h for the buffers of core's
// image and frame types, <library>/buffers.h for a library's own types), e.g.
//
//   inline constexpr BufferName<NormalMap> kNormals{"normals"};
//
// StageBuilder::read(kNormals) then infers the type, so a stage cannot read a buffer as another
// type than its writer's: `Read<DepthMap> depth = builder.read(kNormals);` does not compile
// (tests/core/buffer_name_compile_test.cpp checks that it does not).
#include <string_view>

namespace relight {

template <class T>
class BufferName {
 public:
  using Type = T;
  constexpr explicit BufferName(std::string_view name) : name_(name) {}
  [[nodiscard]] constexpr std::string_view name() const { return name_; }
  friend constexpr bool operator==(BufferName, BufferName) = default;

 private:
  std::string_view name_;  // names are string literals (static storage)
};

}  // namespace relight
