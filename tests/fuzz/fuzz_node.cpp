// Design: fuzz entry point of the camera-node message decoder (pipeline/node/node_wire.h,
// issue 29). The input is a WireHeader's raw bytes followed by the blob bytes, so sizes,
// names and counts lie as a hostile peer's would. The first byte selects a mode: bit 0
// "repair" makes the header plausible (version, known flags, NUL-terminated printable
// names, blob_count = the records present) so that the fuzzer reaches the per-blob value
// checks. Decoding goes into a list of 16 blobs (more: oversized). Properties: a rejected
// message leaves the list empty; an accepted one has blob_count valid, finite blobs and
// re-encodes to exactly the bytes it came from (the floats are bit-exact).
#include <cmath>
#include <cstring>
#include <vector>

#include "pipeline/node/node_wire.h"
#include "tests/fuzz/fuzz_targets.h"

namespace mocap::fuzz {
namespace {

void repair_name(char (&name)[node::kNameBytes]) {
  name[node::kNameBytes - 1] = '\0';
  for (char& c : name) {
    if (c == '\0') break;
    if (c <= ' ' || c > '~') c = 'x';
  }
  if (name[0] == '\0') name[0] = 'n';
}

}  // namespace

int fuzz_node_message(const std::uint8_t* data, std::size_t size) {
  using namespace mocap::node;
  if (size == 0) return 0;
  const bool repair = (data[0] & 1u) != 0;
  ++data;
  --size;
  WireHeader h;
  const std::size_t head = std::min(size, sizeof h);
  std::memcpy(&h, data, head);
  const std::uint8_t* blobs = data + head;
  const std::size_t blob_bytes = size - head;
  if (repair) {
    h.version = kWireVersion;
    h.flags &= kWireReplay;
    repair_name(h.node);
    repair_name(h.camera);
    h.blob_count = static_cast<std::uint32_t>(blob_bytes / node::kBlobRecordBytes);
    if (!std::isfinite(h.background_dn)) h.background_dn = 0.0;
    if (!std::isfinite(h.noise_dn)) h.noise_dn = 0.0;
    if (!std::isfinite(h.threshold_dn)) h.threshold_dn = 0.0;
  }
  detect::BlobList out(16);
  const WireError e = decode_frame(h, blobs, blob_bytes, out);
  fuzz_check(to_string(e) != nullptr, "error without a name");
  if (e != WireError::kOk) {
    fuzz_check(out.size() == 0, "a rejected message left blobs");
    return 0;
  }
  fuzz_check(valid_name(h.node) && valid_name(h.camera), "accepted a bad name");
  fuzz_check(out.size() == h.blob_count && h.blob_count <= 16,
             "accepted a count that is not the list's");
  fuzz_check(blob_bytes == h.blob_count * node::kBlobRecordBytes,
             "accepted bytes of the wrong size");
  for (const detect::Blob& b : out)
    fuzz_check(std::isfinite(b.x_px) && std::isfinite(b.y_px) && b.x_min <= b.x_max,
               "accepted a bad blob");
  std::vector<std::uint8_t> again(blob_bytes + 1);
  const std::uint32_t n = encode_blobs(out, again.data(), again.size());
  fuzz_check(n == h.blob_count, "re-encoding lost blobs");
  fuzz_check(blob_bytes == 0 || std::memcmp(again.data(), blobs, blob_bytes) == 0,
             "re-encoding changed the bytes");
  return 0;
}

}  // namespace mocap::fuzz
