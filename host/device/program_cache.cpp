#include "device/program_cache.hpp"

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "io/io_util.hpp"

namespace tc::device_detail {

namespace {
const char kMagic[8] = {'T', 'C', 'C', 'L', 'B', 'I', 'N', '1'};
// Cache entries larger than this are refused on load (a program binary is a few MB at most).
constexpr uint64_t kMaxBinary = 1ull << 30;
}  // namespace

uint64_t fnv1a64(const void* data, size_t n, uint64_t seed) {
  const unsigned char* p = static_cast<const unsigned char*>(data);
  uint64_t h = seed;
  for (size_t i = 0; i < n; ++i) {
    h ^= p[i];
    h *= 0x100000001b3ull;
  }
  return h;
}

ProgramCache::ProgramCache(std::string dir, const std::string& key) : dir_(std::move(dir)) {
  h1_ = fnv1a64(key.data(), key.size());
  h2_ = fnv1a64(key.data(), key.size(), 0x84222325cbf29ce4ull ^ key.size());
  if (dir_.empty()) return;
  char name[64];
  std::snprintf(name, sizeof name, "%016llx%016llx.clbin", static_cast<unsigned long long>(h1_),
                static_cast<unsigned long long>(h2_));
  path_ = (std::filesystem::path(dir_) / name).string();
}

std::optional<std::vector<unsigned char>> ProgramCache::load() const {
  if (path_.empty()) return std::nullopt;
  std::ifstream in(path_, std::ios::binary);
  if (!in) return std::nullopt;
  char magic[8];
  uint64_t h1 = 0, h2 = 0, n = 0, sum = 0;
  if (!in.read(magic, 8) || std::memcmp(magic, kMagic, 8) != 0) return std::nullopt;
  if (!in.read(reinterpret_cast<char*>(&h1), 8) || !in.read(reinterpret_cast<char*>(&h2), 8)) return std::nullopt;
  if (h1 != h1_ || h2 != h2_) return std::nullopt;
  if (!in.read(reinterpret_cast<char*>(&n), 8) || n == 0 || n > kMaxBinary) return std::nullopt;
  std::error_code ec;
  auto fsize = std::filesystem::file_size(path_, ec);
  if (ec || fsize != 8 + 16 + 8 + n + 8) return std::nullopt;  // checked before allocating n bytes
  std::vector<unsigned char> bin(n);
  if (!in.read(reinterpret_cast<char*>(bin.data()), static_cast<std::streamsize>(n))) return std::nullopt;
  if (!in.read(reinterpret_cast<char*>(&sum), 8) || sum != fnv1a64(bin.data(), bin.size())) return std::nullopt;
  return bin;
}

void ProgramCache::store(const std::vector<unsigned char>& binary) const {
  if (path_.empty()) return;
  try {
    std::error_code ec;
    std::filesystem::create_directories(dir_, ec);
    io::AtomicFile f(path_);
    uint64_t n = binary.size(), sum = fnv1a64(binary.data(), binary.size());
    f.write(kMagic, 8);
    f.write(&h1_, 8);
    f.write(&h2_, 8);
    f.write(&n, 8);
    f.write(binary.data(), binary.size());
    f.write(&sum, 8);
    f.commit();
  } catch (const std::exception&) {
    // A read-only or full cache folder only costs a recompilation next time.
  }
}

}  // namespace tc::device_detail
