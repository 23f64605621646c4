#include "relight/core/image_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <iostream>
#include <limits>
#include <mutex>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <sstream>
#include <streambuf>
#include <string_view>
#include <vector>

#include "relight/core/atomic_file.h"
#include "relight/core/error.h"

namespace relight {

namespace {

// libpng prints its own "libpng error: ..." line on stderr before OpenCV reports failure; the
// user should see one line that names the file, so the decoder's stderr is muted while it runs.
class MutedStderr {
 public:
  MutedStderr() {
    std::fflush(stderr);
    saved_ = ::dup(STDERR_FILENO);
    const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
    if (saved_ >= 0 && null >= 0) ::dup2(null, STDERR_FILENO);
    if (null >= 0) ::close(null);
  }
  ~MutedStderr() {
    if (saved_ < 0) return;
    ::dup2(saved_, STDERR_FILENO);
    ::close(saved_);
  }
  MutedStderr(const MutedStderr&) = delete;
  MutedStderr& operator=(const MutedStderr&) = delete;

 private:
  int saved_ = -1;
};

// Muting fd 2 mutes the whole process: a warning another thread prints while a decoder runs
// (the pipeline's stages beside the prefetching source, which decodes the next frame) was lost.
// So std::cerr goes to a copy of the stderr descriptor taken before any thread or decoder
// exists, which the muting leaves alone, and drops only what the decoding thread itself writes
// there while it decodes (OpenCV's imread reports through std::cerr, libpng through fd 2).
thread_local bool decoding_here = false;

class DescriptorStreambuf final : public std::streambuf {
 public:
  explicit DescriptorStreambuf(int descriptor) : descriptor_(descriptor) {}
  [[nodiscard]] int descriptor() const { return descriptor_; }

 protected:
  int_type overflow(int_type c) override {
    if (traits_type::eq_int_type(c, traits_type::eof())) return traits_type::not_eof(c);
    const char ch = traits_type::to_char_type(c);
    return write_all(&ch, 1) ? c : traits_type::eof();
  }
  std::streamsize xsputn(const char* text, std::streamsize count) override {
    return write_all(text, count) ? count : 0;
  }

 private:
  bool write_all(const char* text, std::streamsize count) const {
    if (decoding_here) return true;
    while (count > 0) {
      const ssize_t written = ::write(descriptor_, text, static_cast<std::size_t>(count));
      if (written < 0 && errno == EINTR) continue;
      if (written <= 0) return false;
      text += written;
      count -= written;
    }
    return true;
  }
  int descriptor_;
};

/// Rebinds std::cerr for the life of the program (this static's), and gives the original back
/// before the standard streams' final flush.
class CerrBesideMutedStderr {
 public:
  CerrBesideMutedStderr() : buffer_(::fcntl(STDERR_FILENO, F_DUPFD_CLOEXEC, 3)) {
    if (copy_ok()) original_ = std::cerr.rdbuf(&buffer_);
  }
  ~CerrBesideMutedStderr() {
    if (original_) std::cerr.rdbuf(original_);
  }
  CerrBesideMutedStderr(const CerrBesideMutedStderr&) = delete;
  CerrBesideMutedStderr& operator=(const CerrBesideMutedStderr&) = delete;

 private:
  [[nodiscard]] bool copy_ok() const { return buffer_.descriptor() >= 0; }  // no stderr at all: leave it
  DescriptorStreambuf buffer_;
  std::streambuf* original_ = nullptr;
};
const CerrBesideMutedStderr cerr_beside_muted_stderr;

ImageSizeLimit& size_limit() {
  static ImageSizeLimit limit;
  return limit;
}

std::mutex& decoder_mutex() {
  static std::mutex mutex;
  return mutex;
}

const char* describe_depth(int cv_depth) {
  switch (cv_depth) {
    case CV_8U: return "8-bit";
    case CV_16U: return "16-bit";
    case CV_32F: return "32-bit float";
    default: return "unsupported";
  }
}

// The formats relight reads, told apart by their first bytes. OpenCV picks its decoder from the
// content alone, among many more (DICOM through GDCM, GDAL rasters, JPEG 2000, ...), so a file
// that is not what its reader expects is refused before any decoder sees it: a 134-byte file
// with a DICOM signature, named depth.png, aborted the process inside GDCM.
enum class ImageFormat { Png, Jpeg, Exr, RadianceHdr };

bool has_signature(std::string_view head, ImageFormat format) {
  switch (format) {
    case ImageFormat::Png: return head.starts_with("\x89PNG\r\n\x1a\n");
    case ImageFormat::Jpeg: return head.starts_with("\xff\xd8\xff");
    case ImageFormat::Exr: return head.starts_with("v/1\x01");
    case ImageFormat::RadianceHdr: return head.starts_with("#?RADIANCE") || head.starts_with("#?RGBE");
  }
  return false;
}

const char* describe(ImageFormat format) {
  switch (format) {
    case ImageFormat::Png: return "PNG";
    case ImageFormat::Jpeg: return "JPEG";
    case ImageFormat::Exr: return "OpenEXR";
    case ImageFormat::RadianceHdr: return "Radiance HDR";
  }
  return "?";
}

/// The file's first bytes: enough for every header the size check reads (a JPEG's frame header
/// may follow tens of kilobytes of EXIF); a header they do not hold is left to the decoder,
/// which fails on it.
std::vector<std::uint8_t> read_head(const std::filesystem::path& path) {
  constexpr std::size_t kHeaderBytes = std::size_t{256} * 1024;
  std::vector<std::uint8_t> head(kHeaderBytes);
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(head.data()), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head;
}

/// Which of the accepted formats the file's first bytes say it is; relight::Error for none.
ImageFormat check_format(const std::filesystem::path& path, std::span<const std::uint8_t> head,
                         std::initializer_list<ImageFormat> accepted) {
  const std::string_view signature(reinterpret_cast<const char*>(head.data()), std::min<std::size_t>(head.size(), 16));
  std::string expected;
  for (const ImageFormat format : accepted) {
    if (has_signature(signature, format)) return format;
    expected += std::string(expected.empty() ? "" : " or ") + describe(format);
  }
  throw Error("cannot decode " + path.string() + ": not a " + expected + " file");
}

constexpr std::int64_t kLargestSide = std::int64_t{1} << 30;

/// A Radiance HDR's resolution line ("-Y 512 +X 1024", after the header's blank line).
std::optional<std::pair<int, int>> radiance_hdr_size(std::span<const std::uint8_t> b) {
  const std::string_view text(reinterpret_cast<const char*>(b.data()), b.size());
  const std::size_t blank = text.find("\n\n");
  if (blank == std::string_view::npos) return std::nullopt;
  const std::size_t end = text.find('\n', blank + 2);
  if (end == std::string_view::npos) return std::nullopt;
  std::istringstream line(std::string(text.substr(blank + 2, end - blank - 2)));
  std::string first_axis, second_axis;
  std::int64_t first = 0, second = 0;
  if (!(line >> first_axis >> first >> second_axis >> second) || first_axis.size() != 2 || second_axis.size() != 2)
    return std::nullopt;
  first = std::clamp<std::int64_t>(first, 0, kLargestSide), second = std::clamp<std::int64_t>(second, 0, kLargestSide);
  // The first axis counts the rows ("-Y H +X W"), unless the image is stored transposed.
  if (first_axis[1] == 'Y') return std::pair{int(second), int(first)};
  return std::pair{int(first), int(second)};
}

/// An OpenEXR header's dataWindow (box2i: xMin, yMin, xMax, yMax), after the magic number and
/// the version: attributes as name, type, size and value until an empty name.
std::optional<std::pair<int, int>> openexr_size(std::span<const std::uint8_t> b) {
  const auto string_at = [&](std::size_t& i) -> std::optional<std::string_view> {
    const auto* begin = reinterpret_cast<const char*>(b.data()) + i;
    const auto* end = std::find(begin, reinterpret_cast<const char*>(b.data()) + b.size(), '\0');
    if (end == reinterpret_cast<const char*>(b.data()) + b.size()) return std::nullopt;
    i += static_cast<std::size_t>(end - begin) + 1;
    return std::string_view(begin, static_cast<std::size_t>(end - begin));
  };
  const auto le32 = [&](std::size_t i) {
    return static_cast<std::int32_t>(std::uint32_t(b[i]) | (std::uint32_t(b[i + 1]) << 8) |
                                     (std::uint32_t(b[i + 2]) << 16) | (std::uint32_t(b[i + 3]) << 24));
  };
  std::size_t i = 8;
  while (i < b.size()) {
    const auto name = string_at(i);
    if (!name || name->empty()) return std::nullopt;
    const auto type = string_at(i);
    if (!type || i + 4 > b.size()) return std::nullopt;
    const std::int32_t size = le32(i);
    i += 4;
    if (size < 0 || i + static_cast<std::size_t>(size) > b.size()) return std::nullopt;
    if (*name == "dataWindow" && *type == "box2i" && size == 16) {
      const std::int64_t width = std::int64_t{le32(i + 8)} - le32(i) + 1,
                         height = std::int64_t{le32(i + 12)} - le32(i + 4) + 1;
      return std::pair{int(std::clamp<std::int64_t>(width, 0, kLargestSide)),
                       int(std::clamp<std::int64_t>(height, 0, kLargestSide))};
    }
    i += static_cast<std::size_t>(size);
  }
  return std::nullopt;
}

/// Width and height from a PNG's IHDR, a JPEG's frame header, a Radiance HDR's resolution line
/// or an OpenEXR's dataWindow; nullopt when the header is missing or cut short.
std::optional<std::pair<int, int>> encoded_size(std::span<const std::uint8_t> b, ImageFormat format) {
  const auto be16 = [&](std::size_t i) { return (int(b[i]) << 8) | int(b[i + 1]); };
  if (format == ImageFormat::Png) {
    // signature (8), chunk length (4), "IHDR", width and height as big-endian 32-bit values.
    if (b.size() < 24 || std::string_view(reinterpret_cast<const char*>(&b[12]), 4) != "IHDR") return std::nullopt;
    const auto be32 = [&](std::size_t i) {
      return (std::uint32_t(b[i]) << 24) | (std::uint32_t(b[i + 1]) << 16) | (std::uint32_t(b[i + 2]) << 8) | b[i + 3];
    };
    const std::uint32_t width = be32(16), height = be32(20);
    constexpr std::uint32_t kLargest = 1u << 30;
    return std::pair{int(std::min(width, kLargest)), int(std::min(height, kLargest))};
  }
  if (format == ImageFormat::RadianceHdr) return radiance_hdr_size(b);
  if (format == ImageFormat::Exr) return openexr_size(b);
  // JPEG: walk the marker segments to the first start-of-frame (SOF0-SOF15 but DHT, JPG, DAC).
  std::size_t i = 2;
  while (i + 4 <= b.size()) {
    if (b[i] != 0xff) return std::nullopt;
    const std::uint8_t marker = b[i + 1];
    if (marker == 0xff) {  // fill byte
      ++i;
      continue;
    }
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd8)) {  // segments without a length
      i += 2;
      continue;
    }
    const std::size_t length = static_cast<std::size_t>(be16(i + 2));
    const bool frame = marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
    if (frame) {
      if (i + 9 > b.size()) return std::nullopt;
      return std::pair{be16(i + 7), be16(i + 5)};
    }
    if (length < 2) return std::nullopt;
    i += 2 + length;
  }
  return std::nullopt;
}

/// Refuses an image whose header claims more than image_size_limit() before a decoder allocates
/// for it (a 30 000 x 30 000 PNG of a few kilobytes asked for 2.7 GB).
void check_size(const std::filesystem::path& path, std::span<const std::uint8_t> head, ImageFormat format) {
  const auto size = encoded_size(head, format);
  if (!size) return;
  const ImageSizeLimit limit = image_size_limit();
  const auto [width, height] = *size;
  if (width > limit.max_side || height > limit.max_side ||
      std::int64_t{width} * std::int64_t{height} > limit.max_pixels)
    throw Error(path.string() + ": a " + std::to_string(width) + "x" + std::to_string(height) + " " + describe(format) +
                " image, over the limit of " + std::to_string(limit.max_side) + " pixels on a side and " +
                std::to_string(limit.max_pixels) + " pixels in all");
}

/// Runs an OpenCV decoder, one at a time and with its stderr muted; an OpenCV exception becomes
/// relight::Error naming `what`.
template <class Decode>
cv::Mat run_decoder(const std::string& what, const Decode& decode) {
  try {
    const std::lock_guard lock(decoder_mutex());
    const MutedStderr muted;
    decoding_here = true;
    struct Done {
      ~Done() { decoding_here = false; }
    } done;
    return decode();
  } catch (const cv::Exception& e) {
    throw Error("cannot decode " + what + ": " + e.err);
  }
}

/// An 8-bit BGR image (OpenCV's decoders' order) as relight's RGB ColorImage.
ColorImage rgb_image(const cv::Mat& bgr) {
  ColorImage image(bgr.cols, bgr.rows);
  cv::Mat wrapped(bgr.rows, bgr.cols, CV_8UC3, image.data());
  cv::cvtColor(bgr, wrapped, cv::COLOR_BGR2RGB);
  return image;
}

cv::Mat read_any(const std::filesystem::path& path, int flags, std::initializer_list<ImageFormat> accepted) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) throw Error("cannot read " + path.string() + ": no such file");
  const std::vector<std::uint8_t> head = read_head(path);
  check_size(path, head, check_format(path, head, accepted));
  // OpenCV keeps EXR behind an opt-in switch since 4.5; relight reads only files it is asked to.
  ::setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  const cv::Mat image = run_decoder(path.string(), [&] { return cv::imread(path.string(), flags); });
  if (image.empty()) throw Error("cannot decode " + path.string() + ": not a readable image (corrupt or truncated?)");
  return image;
}

void write_encoded(const std::filesystem::path& path, const cv::Mat& image, const std::vector<int>& params = {}) {
  ::setenv("OPENCV_IO_ENABLE_OPENEXR", "1", 0);
  std::vector<unsigned char> encoded;
  bool ok = false;
  try {
    ok = cv::imencode(path.extension().string(), image, encoded, params);
  } catch (const cv::Exception& e) {
    throw Error("cannot encode " + path.string() + ": " + e.err);
  }
  if (!ok) throw Error("cannot encode " + path.string() + " (unsupported extension?)");
  write_file_atomically(path, std::as_bytes(std::span<const unsigned char>(encoded)));
}

template <class T>
cv::Mat wrap(const Image<T>& image, int cv_type) {
  // OpenCV only reads through this header; the const_cast never leads to a write.
  return cv::Mat(image.height(), image.width(), cv_type, const_cast<T*>(image.data()));
}

}  // namespace

DepthMap read_depth_png(const std::filesystem::path& path, double scale) {
  const cv::Mat raw = read_any(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_ANYCOLOR, {ImageFormat::Png});
  if (raw.channels() != 1 || raw.depth() != CV_16U) {
    throw Error("depth image " + path.string() + " is " + describe_depth(raw.depth()) + " with " +
                std::to_string(raw.channels()) + " channel(s); expected a 16-bit single-channel PNG");
  }
  DepthMap depth(raw.cols, raw.rows);
  const float inverse_scale = static_cast<float>(1.0 / scale);
  for (int r = 0; r < raw.rows; ++r) {
    const auto* source = raw.ptr<std::uint16_t>(r);
    auto destination = depth.row(r);
    for (int c = 0; c < raw.cols; ++c) destination[c] = static_cast<float>(source[c]) * inverse_scale;
  }
  return depth;
}

void write_depth_png(const std::filesystem::path& path, const DepthMap& depth, double scale) {
  cv::Mat raw(depth.height(), depth.width(), CV_16UC1);
  for (int r = 0; r < depth.height(); ++r) {
    auto* destination = raw.ptr<std::uint16_t>(r);
    const auto source = depth.row(r);
    for (int c = 0; c < depth.width(); ++c) {
      const double value = is_valid_depth(source[c]) ? std::round(source[c] * scale) : 0.0;
      destination[c] = value > 65535.0 ? 0 : static_cast<std::uint16_t>(value);
    }
  }
  write_encoded(path, raw);
}

DepthMap read_depth_exr(const std::filesystem::path& path) {
  const cv::Mat raw = read_any(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE, {ImageFormat::Exr});
  if (raw.channels() != 1 || raw.depth() != CV_32F) {
    throw Error("depth image " + path.string() + " is " + describe_depth(raw.depth()) + " with " +
                std::to_string(raw.channels()) + " channel(s); expected a single-channel float EXR");
  }
  DepthMap depth(raw.cols, raw.rows);
  for (int r = 0; r < raw.rows; ++r) std::copy_n(raw.ptr<float>(r), raw.cols, depth.row(r).data());
  return depth;
}

void write_depth_exr(const std::filesystem::path& path, const DepthMap& depth) {
  // FP32 explicitly: half floats would lose millimetres beyond 2 m.
  write_encoded(path, wrap(depth, CV_32FC1), {cv::IMWRITE_EXR_TYPE, cv::IMWRITE_EXR_TYPE_FLOAT});
}

LabelImage read_label_png(const std::filesystem::path& path) {
  const cv::Mat raw = read_any(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_GRAYSCALE, {ImageFormat::Png});
  if (raw.channels() != 1 || (raw.depth() != CV_16U && raw.depth() != CV_8U)) {
    throw Error("label image " + path.string() + " is " + describe_depth(raw.depth()) + " with " +
                std::to_string(raw.channels()) + " channel(s); expected a single-channel PNG");
  }
  cv::Mat wide;
  raw.convertTo(wide, CV_16U);
  LabelImage labels(raw.cols, raw.rows);
  for (int r = 0; r < raw.rows; ++r) std::copy_n(wide.ptr<std::uint16_t>(r), raw.cols, labels.row(r).data());
  return labels;
}

void write_label_png(const std::filesystem::path& path, const LabelImage& labels) {
  write_encoded(path, wrap(labels, CV_16UC1));
}

ImageSizeLimit image_size_limit() { return size_limit(); }
void set_image_size_limit(const ImageSizeLimit& limit) { size_limit() = limit; }

ColorImage read_color(const std::filesystem::path& path) {
  const cv::Mat raw = read_any(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_COLOR, {ImageFormat::Png, ImageFormat::Jpeg});
  if (raw.depth() != CV_8U) {
    throw Error("colour image " + path.string() + " is " + describe_depth(raw.depth()) + "; expected 8-bit");
  }
  return rgb_image(raw);
}

ColorImage decode_color(std::span<const std::uint8_t> bytes, const std::string& name, int max_side) {
  const std::string_view head(reinterpret_cast<const char*>(bytes.data()), std::min<std::size_t>(bytes.size(), 16));
  std::optional<ImageFormat> format;
  for (const ImageFormat f : {ImageFormat::Png, ImageFormat::Jpeg})
    if (has_signature(head, f)) format = f;
  if (!format) throw Error("cannot decode " + name + ": not a PNG or JPEG image");
  if (bytes.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw Error("cannot decode " + name + ": larger than 2 GiB");
  const auto size = encoded_size(bytes, *format);
  if (!size) throw Error("cannot decode " + name + ": the " + describe(*format) + " header is missing or cut short");
  if (size->first <= 0 || size->second <= 0 || size->first > max_side || size->second > max_side)
    throw Error(name + ": a " + std::to_string(size->first) + "x" + std::to_string(size->second) +
                " image, larger than " + std::to_string(max_side) + " pixels on a side (the limit)");
  // imdecode only reads through this header.
  const cv::Mat encoded(1, static_cast<int>(bytes.size()), CV_8UC1, const_cast<std::uint8_t*>(bytes.data()));
  const cv::Mat raw = run_decoder(name, [&] { return cv::imdecode(encoded, cv::IMREAD_COLOR); });
  if (raw.empty() || raw.depth() != CV_8U)
    throw Error("cannot decode " + name + ": not a readable 8-bit image (corrupt or truncated?)");
  return rgb_image(raw);
}

void write_color(const std::filesystem::path& path, const ColorImage& image) {
  cv::Mat bgr;
  cv::cvtColor(wrap(image, CV_8UC3), bgr, cv::COLOR_RGB2BGR);
  write_encoded(path, bgr);
}

void write_mask(const std::filesystem::path& path, const Mask& mask) { write_encoded(path, wrap(mask, CV_8UC1)); }

RadianceImage read_radiance(const std::filesystem::path& path) {
  const cv::Mat raw = read_any(path, cv::IMREAD_ANYDEPTH | cv::IMREAD_COLOR, {ImageFormat::Exr, ImageFormat::RadianceHdr});
  cv::Mat linear;
  raw.convertTo(linear, CV_32FC3);
  RadianceImage image(raw.cols, raw.rows);
  cv::Mat wrapped(raw.rows, raw.cols, CV_32FC3, image.data());
  cv::cvtColor(linear, wrapped, cv::COLOR_BGR2RGB);
  // An EXR can hold NaN and infinity; every consumer of radiance sums or samples it, where one
  // such pixel silently poisons the result.
  for (int row = 0; row < image.height(); ++row) {
    for (int col = 0; col < image.width(); ++col) {
      const Float3& p = image(row, col);
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        throw Error(path.string() + ": pixel (" + std::to_string(col) + ", " + std::to_string(row) +
                    ") is not finite (NaN or infinity)");
      }
    }
  }
  return image;
}

void write_radiance(const std::filesystem::path& path, const RadianceImage& image) {
  cv::Mat bgr;
  cv::cvtColor(wrap(image, CV_32FC3), bgr, cv::COLOR_RGB2BGR);
  write_encoded(path, bgr);
}

ColorImage depth_preview(const DepthMap& depth, float near_m, float far_m) {
  cv::Mat grey(depth.height(), depth.width(), CV_8UC1);
  cv::Mat valid(depth.height(), depth.width(), CV_8UC1);
  for (int r = 0; r < depth.height(); ++r) {
    for (int c = 0; c < depth.width(); ++c) {
      const float d = depth(r, c);
      const float t = std::clamp((d - near_m) / (far_m - near_m), 0.f, 1.f);
      grey.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(std::lround(255.f * (1.f - t)));
      valid.at<std::uint8_t>(r, c) = is_valid_depth(d) ? 255 : 0;
    }
  }
  cv::Mat coloured;
  cv::applyColorMap(grey, coloured, cv::COLORMAP_TURBO);
  coloured.setTo(cv::Scalar(0, 0, 0), valid == 0);
  ColorImage preview(depth.width(), depth.height());
  cv::Mat wrapped(depth.height(), depth.width(), CV_8UC3, preview.data());
  cv::cvtColor(coloured, wrapped, cv::COLOR_BGR2RGB);
  return preview;
}

ColorImage normal_preview(const NormalMap& normals) {
  ColorImage preview(normals.width(), normals.height());
  auto encode = [](float v) { return static_cast<std::uint8_t>(std::lround(127.5f * (std::clamp(v, -1.f, 1.f) + 1.f))); };
  for (int r = 0; r < normals.height(); ++r) {
    for (int c = 0; c < normals.width(); ++c) {
      const Float3& n = normals(r, c);
      // Camera frame has y down and z forward; flip both so that up-facing and camera-facing
      // surfaces get the familiar light green / blue of normal maps.
      preview(r, c) = is_valid_normal(n) ? Rgb8{encode(n.x), encode(-n.y), encode(-n.z)} : Rgb8{};
    }
  }
  return preview;
}

}  // namespace relight
