// Fuzzes the glTF 2.0 model loader (render/model_io.h, tinygltf underneath): the input is a .glb
// when it starts with the binary magic "glTF", else a .gltf (JSON, buffers as data: URIs).
// relight::Error is the answer to a bad model; any other exception, a crash, a sanitizer report or
// an accepted model the renderer could not index (model_checks.h) is a finding.
#include "fuzz_input.h"
#include "model_checks.h"
#include "relight/render/scene/model_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const auto text = relight::fuzz::as_text(data, size);
  const bool binary = text.substr(0, 4) == "glTF";
  const auto file = relight::fuzz::scratch().write(binary ? "model.glb" : "model.gltf", text);
  try {
    relight::fuzz::check_loaded_model(relight::render::load_model(file));
  } catch (const relight::Error&) {
  }
  return 0;
}
