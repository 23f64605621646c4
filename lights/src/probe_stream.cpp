#include "relight/lights/probe_stream.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "relight/core/error.h"
#include "relight/core/image_io.h"
#include "relight/core/named_values.h"
#include "relight/lights/light_set.h"

namespace relight::lights {

namespace {

namespace fs = std::filesystem;

constexpr std::array<NamedValue<ProbeTiming>, 3> kProbeTimingNames{
    {{"timestamped", ProbeTiming::Timestamped}, {"latest", ProbeTiming::Latest}, {"still", ProbeTiming::Still}}};

std::string lower_extension(const fs::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

bool is_hdr_image(const fs::path& path) {
  const std::string extension = lower_extension(path);
  return extension == ".hdr" || extension == ".exr";
}

bool is_ldr_image(const fs::path& path) {
  const std::string extension = lower_extension(path);
  return extension == ".png" || extension == ".jpg" || extension == ".jpeg";
}

constexpr const char* kProbeImageKinds = " (.hdr, .exr, .png or .jpg)";

struct ProbeListEntry {
  Timestamp timestamp = 0.0;
  fs::path file;
};

/// Frames of a probe list, decoded when asked for.
class ProbeListStream final : public ProbeStream {
 public:
  ProbeListStream(fs::path list, std::vector<ProbeListEntry> entries, const ProbeResponse& response, ProbeTiming timing)
      : list_(std::move(list)), entries_(std::move(entries)), response_(response), timing_(timing) {}

  std::optional<Timestamp> next_timestamp() override {
    if (next_ >= entries_.size()) return std::nullopt;
    return entries_[next_].timestamp;
  }
  void advance() override {
    if (next_ >= entries_.size()) throw LogicError("ProbeListStream::advance past the end");
    ++next_;
  }
  ProbeFrame decode() override {
    if (next_ == 0) throw LogicError("ProbeListStream::decode before advance");
    const ProbeListEntry& entry = entries_[next_ - 1];
    ProbeFrame frame = read_probe_image(entry.file, response_);
    frame.timestamp = entry.timestamp;
    return frame;
  }
  bool rewind() override {
    next_ = 0;
    return true;
  }
  ProbeTiming timing() const override { return timing_; }
  std::string describe() const override { return list_.string(); }

 private:
  fs::path list_;
  std::vector<ProbeListEntry> entries_;
  ProbeResponse response_;
  ProbeTiming timing_;
  std::size_t next_ = 0;
};

std::vector<ProbeListEntry> parse_probe_list(const fs::path& list) {
  std::ifstream in(list);
  if (!in) throw Error("cannot read the probe list " + list.string());
  std::vector<ProbeListEntry> entries;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::string where = list.string() + " line " + std::to_string(line_number);
    std::istringstream fields(line);
    ProbeListEntry entry;
    std::string name;
    if (!(fields >> entry.timestamp >> name) || !std::isfinite(entry.timestamp)) {
      throw Error(where + ": expected \"timestamp filename\"");
    }
    if (!entries.empty() && !(entry.timestamp > entries.back().timestamp)) {
      throw Error(where + ": timestamp " + std::to_string(entry.timestamp) +
                  " is not after the previous one (the list must be sorted by time)");
    }
    entry.file = list.parent_path() / name;
    if (!is_hdr_image(entry.file) && !is_ldr_image(entry.file))
      throw Error(where + ": " + name.append(" is not a probe image").append(kProbeImageKinds));
    std::error_code ec;
    if (!fs::is_regular_file(entry.file, ec)) throw Error(where + ": " + entry.file.string() + " does not exist");
    entries.push_back(std::move(entry));
  }
  if (entries.empty()) throw Error("the probe list " + list.string() + " lists no probe image");
  return entries;
}

}  // namespace

ProbeFrame read_probe_image(const fs::path& path, const ProbeResponse& response) {
  ProbeFrame frame;
  frame.name = path.string();
  if (is_hdr_image(path)) {
    frame.radiance = read_radiance(path);
    // OpenEXR's floats can be negative (a colour transform's undershoot), which is no light
    // (read_radiance refuses NaN and infinity).
    for (Float3& p : frame.radiance.pixels()) p = {std::max(p.x, 0.f), std::max(p.y, 0.f), std::max(p.z, 0.f)};
  } else if (is_ldr_image(path)) {
    LdrProbe ldr = radiance_from_ldr(read_color(path), response);
    frame.radiance = std::move(ldr.radiance);
    frame.clipped_share = ldr.clipped_share;
  } else {
    throw Error(path.string() + ": not a probe image" + kProbeImageKinds);
  }
  return frame;
}

std::unique_ptr<ProbeStream> open_probe_list(const fs::path& list, const ProbeResponse& response) {
  return std::make_unique<ProbeListStream>(list, parse_probe_list(list), response, ProbeTiming::Timestamped);
}

std::unique_ptr<ProbeStream> open_still_probe(const fs::path& image, const ProbeResponse& response) {
  std::error_code ec;
  if (!fs::is_regular_file(image, ec)) throw Error("cannot read the probe " + image.string() + ": no such file");
  if (!is_hdr_image(image) && !is_ldr_image(image))
    throw Error(image.string() + ": not a probe image" + kProbeImageKinds);
  return std::make_unique<ProbeListStream>(image, std::vector<ProbeListEntry>{{0.0, image}}, response,
                                           ProbeTiming::Still);
}

std::unique_ptr<ProbeStream> open_probe_stream(const fs::path& path, const ProbeResponse& response) {
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    const fs::path list = path / "probe.txt";
    if (!fs::is_regular_file(list, ec)) throw Error(path.string() + " is a folder without a probe.txt list");
    return open_probe_list(list, response);
  }
  if (lower_extension(path) == ".txt") return open_probe_list(path, response);
  if (is_hdr_image(path) || is_ldr_image(path)) return open_still_probe(path, response);
  return nullptr;
}

ProbeMatcher::ProbeMatcher(std::unique_ptr<ProbeStream> stream, ProbeMatchOptions options, std::ostream& warnings)
    : stream_(std::move(stream)), options_(options), warnings_(&warnings) {
  if (!stream_) throw LogicError("ProbeMatcher: no stream");
}

ProbeMatcher::~ProbeMatcher() = default;
ProbeMatcher::ProbeMatcher(ProbeMatcher&&) noexcept = default;

const RadianceImage& ProbeMatcher::probe_for(Timestamp rgbd_timestamp) {
  if (!origin_) origin_ = stream_->relative_timestamps() ? rgbd_timestamp + options_.offset_s : 0.0;
  const Timestamp timestamp = rgbd_timestamp - *origin_;  // on the probe stream's clock
  // A looped replay starts its timestamps again: so does a recorded probe stream.
  if (last_request_ && timestamp + options_.tolerance_s < *last_request_ &&
      stream_->timing() == ProbeTiming::Timestamped) {
    if (stream_->rewind()) {
      position_.reset();
      position_decoded_ = false;
    }
  }
  last_request_ = timestamp;
  switch (stream_->timing()) {
    case ProbeTiming::Still:
      if (!current_) {
        stream_->advance();
        take_current_frame();
      }
      break;
    case ProbeTiming::Latest:
      if (stream_->next_timestamp()) {
        stream_->advance();
        take_current_frame();
      } else {
        keep_last("ended", "the probe stream " + stream_->describe() + " delivers no more frames");
      }
      break;
    case ProbeTiming::Timestamped: match_timestamped(timestamp); break;
  }
  return current_->radiance;
}

void ProbeMatcher::match_timestamped(Timestamp timestamp) {
  while (const auto next = stream_->next_timestamp()) {
    // Frames up to the RGB-D frame's time are passed (the last of them is a candidate); the first
    // one after it is taken when it is nearer than that candidate.
    const bool before = *next <= timestamp;
    if (!before && position_ && timestamp - *position_ <= *next - timestamp) break;
    stream_->advance();
    position_ = *next;
    position_decoded_ = false;
    if (!before) break;
  }
  const double gap = position_ ? std::abs(timestamp - *position_) : INFINITY;
  if (gap <= options_.tolerance_s) {
    if (!position_decoded_) take_current_frame();
    position_decoded_ = true;  // a frame that failed is not tried again
    return;
  }
  std::ostringstream trouble;
  trouble << std::fixed << std::setprecision(3);
  if (!stream_->next_timestamp() && position_ && timestamp > *position_) {
    trouble << "the probe stream " << stream_->describe() << " ended at t = " << *position_
            << " s, before the RGB-D frame at t = " << timestamp << " s";
    keep_last("ended", trouble.str());
  } else {
    trouble << "the probe stream " << stream_->describe() << " has no frame within " << options_.tolerance_s
            << " s of the RGB-D frame at t = " << timestamp << " s";
    keep_last("gap", trouble.str());
  }
}

void ProbeMatcher::take_current_frame() {
  ProbeFrame frame;
  try {
    frame = stream_->decode();
  } catch (const Error& error) {
    keep_last("unreadable", error.what());
    return;
  }
  consider(std::move(frame));
}

void ProbeMatcher::consider(ProbeFrame frame) {
  double power = 0.0;
  for (const Float3& p : frame.radiance.pixels()) power += luminance({p.x, p.y, p.z});
  if (!(power > 0.0)) {
    keep_last("black", frame.name + ": the probe is black (no light to extract)");
    return;
  }
  max_clipped_ = std::max(max_clipped_, frame.clipped_share);
  const auto percent = [](double share) { return std::to_string(static_cast<int>(std::lround(100.0 * share))); };
  if (frame.clipped_share > options_.clipped_unusable) {
    keep_last("clipped", frame.name + ": the probe is " + percent(frame.clipped_share) +
                             " % saturated (over-exposed: lower the probe camera's exposure)");
    return;
  }
  if (frame.clipped_share > options_.clipped_warning && warned_.insert("clipped-share").second) {
    *warnings_ << "relight: warning: the probe " << frame.name << " has " << percent(frame.clipped_share)
               << " % of its pixels saturated: their radiance is extrapolated (probe_response.h), the light"
               << " sources may be too dark; an HDR probe avoids this (said once)\n";
  }
  current_ = std::move(frame);
  ++used_;
}

void ProbeMatcher::keep_last(const std::string& kind, const std::string& trouble) {
  if (!current_) throw Error(trouble);
  ++kept_;
  if (std::find(kept_reasons_.begin(), kept_reasons_.end(), kind) == kept_reasons_.end()) {
    kept_reasons_.push_back(kind);
  }
  if (warned_.insert(kind).second) {
    *warnings_ << "relight: warning: " << trouble << ": keeping the last good probe " << current_->name
               << " (said once)\n";
  }
}

nlohmann::ordered_json ProbeMatcher::summary() const {
  nlohmann::ordered_json out;
  out["source"] = stream_->describe();
  out["timing"] = std::string(name_of(kProbeTimingNames, stream_->timing()));
  out["probes_used"] = used_;
  out["frames_kept_last_probe"] = kept_;
  out["kept_because"] = kept_reasons_;
  out["max_clipped_share"] = max_clipped_;
  return out;
}

}  // namespace relight::lights
