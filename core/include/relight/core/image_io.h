#pragma once
// Image files through OpenCV's codecs (kept out of this header). Every reader throws
// relight::Error with the file name and the reason, and decodes only the formats it names below,
// told by their signature (OpenCV would hand any file to whichever of its many decoders claims
// it); every writer is atomic (see atomic_file.h) and picks the format from the extension.
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>

#include "relight/core/image.h"

namespace relight {

/// 16-bit single-channel PNG depth, metres = value / scale (TUM: 5000, OpenNI: 1000); 0 = missing.
DepthMap read_depth_png(const std::filesystem::path& path, double scale);
/// Writes metres * scale rounded to uint16; invalid or out-of-range depth becomes 0.
void write_depth_png(const std::filesystem::path& path, const DepthMap& depth, double scale);

/// Single-channel 32-bit float OpenEXR depth in metres (exact ground truth; 0 = missing).
DepthMap read_depth_exr(const std::filesystem::path& path);
void write_depth_exr(const std::filesystem::path& path, const DepthMap& depth);

/// 16-bit single-channel PNG labels (material ids, cluster ids), stored as they are.
LabelImage read_label_png(const std::filesystem::path& path);
void write_label_png(const std::filesystem::path& path, const LabelImage& labels);

/// The largest image the readers below decode: a file whose header claims more is refused with a
/// line naming it and the limit before anything is allocated for it. 16384 on a side and 2^26
/// pixels (a 16k x 4k probe, an 8k x 8k texture) by default.
struct ImageSizeLimit {
  int max_side = 16384;
  std::int64_t max_pixels = std::int64_t{1} << 26;
};
[[nodiscard]] ImageSizeLimit image_size_limit();
/// For programs that must stay smaller (the fuzz targets); set it before any reading starts.
void set_image_size_limit(const ImageSizeLimit& limit);

/// 8-bit colour, PNG or JPEG. Grey images are expanded to RGB; 16-bit images are rejected.
ColorImage read_color(const std::filesystem::path& path);
void write_color(const std::filesystem::path& path, const ColorImage& image);
/// 8-bit colour from the bytes of a PNG or JPEG file held in memory (a glTF model's embedded
/// texture); `name` says in errors what the bytes are. The image's size is read from its header
/// first, and one wider or higher than `max_side` is refused before anything is allocated for it.
ColorImage decode_color(std::span<const std::uint8_t> bytes, const std::string& name, int max_side);
void write_mask(const std::filesystem::path& path, const Mask& mask);

/// Linear HDR radiance: Radiance .hdr or OpenEXR .exr. A NaN or infinite pixel is an error.
RadianceImage read_radiance(const std::filesystem::path& path);
void write_radiance(const std::filesystem::path& path, const RadianceImage& image);

/// False-colour previews for people to look at (not for re-reading).
ColorImage depth_preview(const DepthMap& depth, float near_m = 0.4f, float far_m = 4.5f);
ColorImage normal_preview(const NormalMap& normals);

}  // namespace relight
