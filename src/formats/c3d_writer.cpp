// Design: see c3d_writer.h. Everything is little-endian (processor type Intel) and built
// byte by byte, so the file does not depend on the host's struct layout. Parameter
// records: name length, group id (negative for a group, the group's |id| for its
// parameters), name, a 16-bit offset from that offset word to the next record (0 ends
// the section), then for a parameter: element type (-1 char, 2 int16, 4 float), the
// dimensions and the data (first dimension varies fastest), and a description.
#include "formats/c3d_writer.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>

namespace mocap {
namespace {

constexpr std::size_t kBlock = 512;
constexpr int kProcessorIntel = 84;  // 83 + processor type 1

void put_u8(std::vector<unsigned char>& b, int v) { b.push_back(static_cast<unsigned char>(v)); }
void put_i16(std::vector<unsigned char>& b, int v) {
  const auto u = static_cast<std::uint16_t>(v);
  b.push_back(static_cast<unsigned char>(u & 0xFF));
  b.push_back(static_cast<unsigned char>(u >> 8));
}
void put_f32(std::vector<unsigned char>& b, float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  for (int i = 0; i < 4; ++i) b.push_back(static_cast<unsigned char>((u >> (8 * i)) & 0xFF));
}
void set_i16(std::vector<unsigned char>& b, std::size_t at, int v) {
  const auto u = static_cast<std::uint16_t>(v);
  b[at] = static_cast<unsigned char>(u & 0xFF);
  b[at + 1] = static_cast<unsigned char>(u >> 8);
}
void set_f32(std::vector<unsigned char>& b, std::size_t at, float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, sizeof u);
  for (std::size_t i = 0; i < 4; ++i) b[at + i] = static_cast<unsigned char>((u >> (8 * i)) & 0xFF);
}

// Builds the parameter records; each record's "next" offset is patched when the next
// record starts, the last one stays 0.
class ParameterSection {
 public:
  void group(int id, const std::string& name, const std::string& description) {
    begin(-id, name);
    put_u8(bytes_, static_cast<int>(description.size()));
    bytes_.insert(bytes_.end(), description.begin(), description.end());
  }
  void int16(int group, const std::string& name, const std::vector<int>& values, bool array,
             const std::string& description) {
    std::vector<unsigned char> data;
    for (int v : values) put_i16(data, v);
    param(group, name, 2,
          array ? std::vector<int>{static_cast<int>(values.size())} : std::vector<int>{}, data,
          description);
  }
  void real(int group, const std::string& name, float value, const std::string& description) {
    std::vector<unsigned char> data;
    put_f32(data, value);
    param(group, name, 4, {}, data, description);
  }
  // One string: dimension (length).
  void string(int group, const std::string& name, const std::string& value,
              const std::string& description) {
    param(group, name, -1, {static_cast<int>(value.size())},
          std::vector<unsigned char>(value.begin(), value.end()), description);
  }
  // Strings padded with blanks to the longest: dimensions (length, count). A dimension is
  // one byte, so at most 255 strings of at most 255 characters (checked by the caller).
  void text(int group, const std::string& name, const std::vector<std::string>& values,
            const std::string& description) {
    std::size_t len = 1;
    for (const std::string& v : values) len = std::max(len, v.size());
    std::vector<unsigned char> data;
    for (const std::string& v : values) {
      std::string padded = v;
      padded.resize(len, ' ');
      data.insert(data.end(), padded.begin(), padded.end());
    }
    param(group, name, -1, {static_cast<int>(len), static_cast<int>(values.size())}, data,
          description);
  }
  // A list longer than one parameter holds (255 strings) continues in NAME2, NAME3, ...
  // (the C3D convention of POINT:LABELS2 etc.): 255 strings per parameter, in order.
  void text_list(int group, const std::string& name, const std::vector<std::string>& values,
                 const std::string& description) {
    for (std::size_t first = 0, part = 1; first < values.size();
         first += kC3dLabelsPerParameter, ++part) {
      const std::size_t end = std::min(values.size(), first + kC3dLabelsPerParameter);
      text(group, part == 1 ? name : name + std::to_string(part),
           std::vector<std::string>(values.begin() + static_cast<std::ptrdiff_t>(first),
                                    values.begin() + static_cast<std::ptrdiff_t>(end)),
           description);
    }
  }
  // Closes the section (the last record keeps offset 0). The name of the first record
  // longer than its 16-bit signed offset word can span, or empty.
  const std::string& oversized() noexcept {
    check_last();
    return oversized_;
  }
  const std::vector<unsigned char>& bytes() const noexcept { return bytes_; }

 private:
  // The record that starts now ends the previous one: its offset word points here.
  void check_last() {
    if (last_offset_at_ != 0 && bytes_.size() - last_offset_at_ > kMaxRecordOffset &&
        oversized_.empty())
      oversized_ = last_name_;
  }
  void begin(int id, const std::string& name) {
    check_last();
    if (last_offset_at_ != 0 && oversized_.empty())
      set_i16(bytes_, last_offset_at_, static_cast<int>(bytes_.size() - last_offset_at_));
    last_name_ = name;
    put_u8(bytes_, static_cast<int>(name.size()));
    put_u8(bytes_, id);
    bytes_.insert(bytes_.end(), name.begin(), name.end());
    last_offset_at_ = bytes_.size();
    put_i16(bytes_, 0);
  }
  void param(int group, const std::string& name, int type, const std::vector<int>& dims,
             const std::vector<unsigned char>& data, const std::string& description) {
    begin(group, name);
    put_u8(bytes_, type);
    put_u8(bytes_, static_cast<int>(dims.size()));
    for (int d : dims) put_u8(bytes_, d);
    bytes_.insert(bytes_.end(), data.begin(), data.end());
    put_u8(bytes_, static_cast<int>(description.size()));
    bytes_.insert(bytes_.end(), description.begin(), description.end());
  }
  static constexpr std::size_t kMaxRecordOffset = 32767;  // a signed 16-bit word
  std::vector<unsigned char> bytes_;
  std::size_t last_offset_at_ = 0;
  std::string last_name_, oversized_;
};

// The parameter records; `oversized` names a record too long for its offset word.
std::vector<unsigned char> parameters(const TrajectoryLayout& l, int data_start_block,
                                      std::string& oversized) {
  const int used = static_cast<int>(l.labels.size());
  const auto last = static_cast<std::int64_t>(l.first_frame + l.frame_count - 1);
  const float rate = static_cast<float>(l.rate_hz);
  ParameterSection p;
  constexpr int kPoint = 1, kAnalog = 2, kTrial = 3;
  p.group(kPoint, "POINT", "3D point parameters");
  p.int16(kPoint, "USED", {used}, false, "number of trajectories");
  p.real(kPoint, "SCALE", kC3dPointScale, "negative: floating-point data; residual unit");
  p.real(kPoint, "RATE", rate, "frames per second");
  p.int16(kPoint, "DATA_START", {data_start_block}, false, "first block of the 3D data");
  p.int16(kPoint, "FRAMES", {static_cast<int>(l.frame_count)}, false, "number of frames");
  p.string(kPoint, "UNITS", "mm", "units of the coordinates");
  p.text_list(kPoint, "LABELS", l.labels, "BODY_mN: marker N of body BODY (targets.yaml)");
  p.text_list(kPoint, "DESCRIPTIONS",
              l.descriptions.size() == l.labels.size() ? l.descriptions : l.labels,
              "trajectory descriptions");
  p.group(kAnalog, "ANALOG", "analog data parameters");
  p.int16(kAnalog, "USED", {0}, false, "no analog channels");
  p.real(kAnalog, "RATE", rate, "analog rate (no channels)");
  p.group(kTrial, "TRIAL", "trial parameters");
  const auto lo = [](std::int64_t v) { return static_cast<int>(v & 0xFFFF); };
  const auto hi = [](std::int64_t v) { return static_cast<int>((v >> 16) & 0xFFFF); };
  p.int16(kTrial, "ACTUAL_START_FIELD", {lo(l.first_frame), hi(l.first_frame)}, true,
          "first frame (low word, high word)");
  p.int16(kTrial, "ACTUAL_END_FIELD", {lo(last), hi(last)}, true,
          "last frame (low word, high word)");
  p.int16(kTrial, "CAMERA_RATE", {static_cast<int>(std::lround(l.rate_hz))}, false,
          "camera frames per second (rounded)");
  oversized = p.oversized();
  return p.bytes();
}

}  // namespace

Expected<std::vector<unsigned char>> c3d_header_and_parameters(const TrajectoryLayout& l) {
  if (l.labels.empty() || l.labels.size() > static_cast<std::size_t>(kC3dMaxPoints)) {
    return make_error("C3D", "POINT:LABELS",
                      "needs 1 to " + std::to_string(kC3dMaxPoints) + " trajectories, got " +
                          std::to_string(l.labels.size()));
  }
  for (const std::string& s : l.labels) {
    if (s.empty() || s.size() > 255)
      return make_error("C3D", "POINT:LABELS", "label '" + s + "' must have 1 to 255 characters");
  }
  if (l.descriptions.size() == l.labels.size()) {  // else the labels are the descriptions
    for (const std::string& s : l.descriptions) {
      if (s.size() > 255)
        return make_error("C3D", "POINT:DESCRIPTIONS",
                          "description '" + s + "' has more than 255 characters");
    }
  }
  if (!(l.rate_hz > 0.0) || !std::isfinite(l.rate_hz))
    return make_error("C3D", "POINT:RATE", "frame rate must be positive");
  if (l.frame_count < 1 || l.first_frame < 1 || l.first_frame + l.frame_count - 1 > kC3dMaxFrame) {
    return make_error("C3D", "POINT:FRAMES",
                      "frames " + std::to_string(l.first_frame) + ".." +
                          std::to_string(l.first_frame + l.frame_count - 1) +
                          " do not fit C3D's 16-bit frame numbers (1..65535); split the recording");
  }
  // The parameter size does not depend on DATA_START's value: build once to size it.
  std::string oversized;
  const std::size_t param_bytes = 4 + parameters(l, 0, oversized).size();
  if (!oversized.empty()) {
    const bool labels = oversized.rfind("LABELS", 0) == 0;
    return make_error("C3D", "POINT:" + oversized,
                      std::string("the ") + (labels ? "labels" : "descriptions") +
                          " are too long for one parameter record (at most 32767 bytes: 255 "
                          "texts of up to 128 characters); shorten the body names");
  }
  const std::size_t param_blocks = (param_bytes + kBlock - 1) / kBlock;
  if (param_blocks > 255) {
    return make_error("C3D", "parameters",
                      "the parameter section needs " + std::to_string(param_blocks) +
                          " blocks, at most 255 fit (shorten the labels)");
  }
  const int data_start = static_cast<int>(2 + param_blocks);

  std::vector<unsigned char> out(kBlock * (1 + param_blocks), 0);
  out[0] = 2;     // first block of the parameter section
  out[1] = 0x50;  // C3D key
  set_i16(out, 2, static_cast<int>(l.labels.size()));
  set_i16(out, 4, 0);  // analog measurements per 3D frame
  set_i16(out, 6, static_cast<int>(l.first_frame));
  set_i16(out, 8, static_cast<int>(l.first_frame + l.frame_count - 1));
  set_i16(out, 10, 0);  // maximum interpolation gap
  set_f32(out, 12, kC3dPointScale);
  set_i16(out, 16, data_start);
  set_i16(out, 18, 0);  // analog samples per 3D frame
  set_f32(out, 20, static_cast<float>(l.rate_hz));
  set_i16(out, 298, 12345);  // word 150: 4-character event labels; 0 events follow
  // Parameter section header (block 2): two ignored bytes, block count, processor type.
  out[kBlock + 0] = 1;
  out[kBlock + 1] = 0x50;
  out[kBlock + 2] = static_cast<unsigned char>(param_blocks);
  out[kBlock + 3] = kProcessorIntel;
  const std::vector<unsigned char> params = parameters(l, data_start, oversized);
  std::copy(params.begin(), params.end(), out.begin() + static_cast<std::ptrdiff_t>(kBlock + 4));
  return out;
}

Expected<C3dWriter> C3dWriter::open(const std::string& path, const TrajectoryLayout& layout) {
  auto head = c3d_header_and_parameters(layout);
  if (!head) {  // name the file instead of the generic "C3D"
    const std::string& m = head.error().message;
    return make_error(path, "", m.substr(std::min(m.size(), std::string("C3D: ").size())));
  }
  auto file = formats_detail::ExportFile::open(path);
  if (!file) return file.error();
  C3dWriter w(std::move(file).value());
  w.file_.write(head->data(), head->size());  // a failure is reported by close()
  w.points_ = layout.labels.size();
  w.frame_bytes_.assign(16 * w.points_, 0);
  w.frames_declared_ = layout.frame_count;
  return w;
}

bool C3dWriter::write_frame(const TrajectorySample* samples) noexcept {
  if (file_.failed()) return false;
  const float scale = std::fabs(kC3dPointScale);
  for (std::size_t i = 0; i < points_; ++i) {
    const TrajectorySample& s = samples[i];
    const std::size_t at = 16 * i;
    if (!s.valid) {
      set_f32(frame_bytes_, at, 0.0f);
      set_f32(frame_bytes_, at + 4, 0.0f);
      set_f32(frame_bytes_, at + 8, 0.0f);
      set_f32(frame_bytes_, at + 12, -1.0f);
      continue;
    }
    const double r = std::round(s.residual_mm / static_cast<double>(scale));
    const int residual = static_cast<int>(std::clamp(std::isfinite(r) ? r : 255.0, 1.0, 255.0));
    const int word = ((s.cameras & 0x7F) << 8) | residual;
    set_f32(frame_bytes_, at, static_cast<float>(s.X_mm.x()));
    set_f32(frame_bytes_, at + 4, static_cast<float>(s.X_mm.y()));
    set_f32(frame_bytes_, at + 8, static_cast<float>(s.X_mm.z()));
    set_f32(frame_bytes_, at + 12, static_cast<float>(word));
  }
  if (!file_.write(frame_bytes_.data(), frame_bytes_.size())) return false;
  ++frames_written_;
  return true;
}

Expected<void> C3dWriter::close() {
  static const unsigned char kZeros[kBlock] = {};
  file_.write(kZeros, (kBlock - file_.bytes_written() % kBlock) % kBlock);  // whole blocks
  if (auto r = file_.close(); !r) return r;
  if (frames_written_ != frames_declared_) {
    return make_error(file_.path(), "POINT:FRAMES",
                      "wrote " + std::to_string(frames_written_) + " frames, declared " +
                          std::to_string(frames_declared_));
  }
  return {};
}

}  // namespace mocap
