// A set of 64-bit keys with no key all ones (the host tail's edges, a << 32 | b with a, b >= 0):
// open addressing, linear probing, erase by backward shift, at most half full.
//
// Why our own: the greedy host tail (SequentialRun, sequential.cpp) inserts and erases an edge
// for every queue entry; std::unordered_set allocates and frees a node for each, a visible share
// of the tail's time in a profile (bench/README.md). The standard library has no flat hash set, and one header is less
// than a new dependency (Boost's unordered_flat_set) for the same thing.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace tc::sequential_detail {

class EdgeKeySet {
 public:
  // Whether key is in the set; inserts it when not (as std::unordered_set::insert(...).second).
  bool insert(uint64_t key) {
    if (2 * (size_ + 1) > slots_.size()) grow();
    size_t i = home(key);
    while (slots_[i] != kEmpty) {
      if (slots_[i] == key) return false;
      i = (i + 1) & mask_;
    }
    slots_[i] = key;
    ++size_;
    return true;
  }
  // Removes key; returns whether it was there.
  bool erase(uint64_t key) {
    if (size_ == 0) return false;
    size_t i = home(key);
    while (slots_[i] != key) {
      if (slots_[i] == kEmpty) return false;
      i = (i + 1) & mask_;
    }
    // backward shift: move up every later key of the run that may live at i
    for (size_t j = (i + 1) & mask_; slots_[j] != kEmpty; j = (j + 1) & mask_) {
      const size_t h = home(slots_[j]);
      // j's key may move to i when its home is not in the cyclic range (i, j]
      if (((j - h) & mask_) >= ((j - i) & mask_)) {
        slots_[i] = slots_[j];
        i = j;
      }
    }
    slots_[i] = kEmpty;
    --size_;
    return true;
  }
  bool contains(uint64_t key) const {
    if (size_ == 0) return false;
    for (size_t i = home(key); slots_[i] != kEmpty; i = (i + 1) & mask_)
      if (slots_[i] == key) return true;
    return false;
  }
  size_t size() const { return size_; }
  void clear() {
    slots_.assign(slots_.size(), kEmpty);
    size_ = 0;
  }

 private:
  static constexpr uint64_t kEmpty = ~uint64_t(0);
  size_t home(uint64_t key) const { return size_t((key * 0x9E3779B97F4A7C15ull) >> shift_); }
  void grow() {
    std::vector<uint64_t> old;
    old.swap(slots_);
    const size_t n = old.empty() ? 1024 : 2 * old.size();
    slots_.assign(n, kEmpty);
    mask_ = n - 1;
    shift_ = 64;
    for (size_t m = n; m > 1; m >>= 1) --shift_;
    size_ = 0;
    for (uint64_t k : old)
      if (k != kEmpty) insert(k);
  }

  std::vector<uint64_t> slots_;
  size_t mask_ = 0, size_ = 0;
  int shift_ = 64;
};

}  // namespace tc::sequential_detail
