// Fuzzes the OBJ/MTL model loader (render/model_io.h, tinyobjloader underneath): the input is an
// OBJ file, optionally followed by a "----" line and the MTL file it names as `mtllib model.mtl`
// (see fuzz_input.h). relight::Error is the answer to a bad model; any other exception, a crash,
// a sanitizer report or an accepted model the renderer could not index (model_checks.h) is a
// finding.
#include "fuzz_input.h"
#include "model_checks.h"
#include "relight/render/scene/model_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using relight::fuzz::scratch;
  const auto files = relight::fuzz::split_files(relight::fuzz::as_text(data, size));
  const auto obj = scratch().write("model.obj", files[0]);
  if (files.size() > 1) {
    scratch().write("model.mtl", files[1]);
  } else {
    scratch().remove("model.mtl");
  }
  try {
    relight::fuzz::check_loaded_model(relight::render::load_model(obj));
  } catch (const relight::Error&) {
  }
  return 0;
}
