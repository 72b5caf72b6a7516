// Design: the blob file of a blob recording, `blobs/<camera>.blobs` (docs/formats.md,
// "Blob recordings"): the detector's blob list of one camera per frame, in place of images.
// Binary, little-endian, versioned, CRC-protected, append-only:
//   file header  magic "MOCAPBLB", version, header and record sizes, camera name, image
//                size, the writer's blob capacity, CRC-32 of the header;
//   frame chunk  sync "BLBF", blob count, frame, timestamp_ns, the detector's image
//                levels (3 x f64), count fixed 60-byte blob records, CRC-32 of the chunk.
// Every field of detect::Blob is stored bit-exact (f64 centroid, f32 shape, integer box
// and flags) with the frame's BlobList::Levels, so the tracker given a blob file computes
// exactly what it computes after detecting the images.
// Writer: one write() per chunk (a chunk is either whole on disk or cut off at the
// tail), fdatasync() at most every sync_interval_ns (power loss loses at most that much)
// and at close; a failed write cuts the file back to its last whole chunk (full disk),
// so the file always ends on a whole chunk as far as the writer knows.
// Reader: open() scans the file once, checking every chunk's framing and CRC, and keeps an
// index (frame -> offset). A torn tail (the last chunk incomplete or its CRC wrong, a
// crash or power loss while writing) is reported and ignored; damaged bytes in the
// middle are skipped up to the next chunk whose sync word and CRC are valid, and
// counted and reported (one line naming the file and byte offsets each); the frames in
// them read as missing (a dropped frame). Magic, version and header errors are
// errors. Sizes from the file are bounded before use (blob count <= the header's
// capacity <= kMaxBlobFileBlobs). load() preads one chunk (thread-safe; allocation-free
// once the caller's scratch buffer has grown to the largest chunk).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/expected.h"
#include "detect/blob.h"

namespace mocap {

inline constexpr std::uint16_t kBlobFileVersion = 1;
inline constexpr std::size_t kBlobRecordBytes = 60;           // version 1's record
inline constexpr std::size_t kBlobChunkHeaderBytes = 48;      // sync .. threshold_dn
inline constexpr std::uint32_t kMaxBlobFileBlobs = 1u << 20;  // = detection.max_blobs' bound

struct BlobFileInfo {
  std::string camera;
  int width = 0, height = 0;
  std::uint32_t max_blobs = 0;  // the writer's capacity: no chunk holds more
  std::uint16_t version = 0;
  std::uint32_t record_bytes = 0;
};

class BlobFileWriter {
 public:
  // Creates `path` (must not exist) and writes the header. width/height <= 65535.
  static Expected<BlobFileWriter> create(const std::string& path, const BlobFileInfo& info,
                                         std::int64_t sync_interval_ns = 1'000'000'000,
                                         std::uint64_t byte_budget = 0);
  BlobFileWriter(BlobFileWriter&& other) noexcept;
  BlobFileWriter& operator=(BlobFileWriter&& other) noexcept;
  BlobFileWriter(const BlobFileWriter&) = delete;
  BlobFileWriter& operator=(const BlobFileWriter&) = delete;
  ~BlobFileWriter();

  // Appends the chunk of one frame (frames strictly increasing). On a failed write the
  // file is cut back to its last whole chunk and the error names the file. Allocates
  // nothing (the chunk buffer is sized at create()).
  Expected<void> append(std::int64_t frame, std::int64_t timestamp_ns,
                        const detect::BlobList& blobs);
  // fdatasync and close (idempotent).
  Expected<void> close();

  std::uint64_t bytes() const noexcept { return length_; }
  const std::string& path() const noexcept { return path_; }

 private:
  BlobFileWriter() = default;
  bool write_all(const std::uint8_t* data, std::size_t n) noexcept;

  std::string path_;
  int fd_ = -1;
  std::uint32_t max_blobs_ = 0;
  std::uint64_t length_ = 0;  // bytes of whole chunks (and the header)
  std::int64_t last_frame_ = -1;
  std::int64_t sync_interval_ns_ = 0;
  std::int64_t last_sync_ns_ = 0;
  std::uint64_t byte_budget_ = 0;  // test hook: ENOSPC past this many bytes (0: off)
  std::vector<std::uint8_t> chunk_;
};

class BlobFileReader {
 public:
  struct Chunk {
    std::int64_t frame = 0;
    std::int64_t timestamp_ns = 0;
    std::uint64_t offset = 0;
    std::uint32_t count = 0;
  };
  // Scans the file. Problems that leave the rest readable (torn tail, damaged chunks)
  // are appended to `warnings`, one line each.
  static Expected<BlobFileReader> open(const std::string& path, std::vector<std::string>& warnings);
  BlobFileReader(BlobFileReader&& other) noexcept;
  BlobFileReader& operator=(BlobFileReader&&) = delete;
  BlobFileReader(const BlobFileReader&) = delete;
  BlobFileReader& operator=(const BlobFileReader&) = delete;
  ~BlobFileReader();

  const BlobFileInfo& info() const noexcept { return info_; }
  const std::vector<Chunk>& chunks() const noexcept { return chunks_; }
  std::uint64_t damaged_bytes() const noexcept { return damaged_bytes_; }
  std::uint64_t torn_bytes() const noexcept { return torn_bytes_; }
  std::uint64_t damaged_regions() const noexcept { return damaged_regions_; }

  // The chunk of `frame`, or null (the camera dropped the frame).
  const Chunk* find(std::int64_t frame) const noexcept;
  // Reads `chunk` into `out` (cleared; blobs beyond its capacity are refused as
  // BoundedList counts them) with its levels. An error names the file and offset if the
  // bytes changed since open(). `scratch` grows to the chunk's size once.
  Expected<void> load(const Chunk& chunk, detect::BlobList& out,
                      std::vector<std::uint8_t>& scratch) const;

 private:
  BlobFileReader() = default;

  std::string path_;
  int fd_ = -1;
  BlobFileInfo info_;
  std::uint64_t data_start_ = 0;
  std::vector<Chunk> chunks_;  // frames strictly increasing
  std::uint64_t damaged_bytes_ = 0, torn_bytes_ = 0, damaged_regions_ = 0;
};

// Decodes/encodes one blob record (exposed for tests and the fuzz target).
void encode_blob_record(const detect::Blob& b, std::uint8_t* out) noexcept;
detect::Blob decode_blob_record(const std::uint8_t* in) noexcept;

}  // namespace mocap
