// Compiled twice by tests/core/compile/expect_compile_error.cmake: as it is, it must compile;
// with RELIGHT_READ_WITH_WRONG_TYPE, a stage that takes the normals for a depth map must not.
#include "relight/core/buffers.h"
#include "relight/core/frame_graph.h"

namespace relight {

class NormalsReader final : public Stage {
 public:
  [[nodiscard]] std::string name() const override { return "normals_reader"; }
  void declare(StageBuilder& builder) override {
#ifdef RELIGHT_READ_WITH_WRONG_TYPE
    Read<DepthMap> normals = builder.read(kNormals);
#else
    Read<NormalMap> normals = builder.read(kNormals);
#endif
    normals_ = normals;
  }
  void run(StageContext&) override {}

 private:
  Read<NormalMap> normals_;
};

}  // namespace relight
