// On-disk cache of compiled OpenCL program binaries.
//
// An entry is keyed by a 128-bit hash of (device name, vendor, driver version, platform version,
// build options, expanded source). File layout: "TCCLBIN1", the 16-byte key hash, the binary
// length (u64), the binary, a 64-bit FNV-1a checksum of the binary. Entries are written
// atomically (temporary file + rename); anything unreadable, truncated or failing the checks
// is ignored so the caller builds from source.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace tc::device_detail {

uint64_t fnv1a64(const void* data, size_t n, uint64_t seed = 0xcbf29ce484222325ull);

class ProgramCache {
 public:
  // dir "" disables the cache.
  ProgramCache(std::string dir, const std::string& key);
  std::optional<std::vector<unsigned char>> load() const;
  // Best effort: failures to create the folder or write the file are silent.
  void store(const std::vector<unsigned char>& binary) const;
  const std::string& path() const { return path_; }

 private:
  std::string dir_, path_;
  uint64_t h1_ = 0, h2_ = 0;
};

}  // namespace tc::device_detail
