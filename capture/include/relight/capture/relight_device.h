#pragma once
// What relight's own OpenNI2 driver (relight://synthetic, relight://tum/<folder>) tells a client
// beyond frames, through device properties of its own (ids outside OpenNI2's ranges).
namespace relight::capture {

/// char[] (NUL-terminated): a folder holding the device scene's scene.json (as `relight synth`
/// writes it: camera, tag layout, lights) and probe.hdr, so that `relight live` lights and
/// tracks a virtual device as it would replay the same sequence; "" or unsupported: none. The
/// synthetic device writes the folder when first asked and removes it when it closes.
inline constexpr int kRelightDeviceSceneFolderProperty = 0x52454C01;  // "REL" 1

}  // namespace relight::capture
