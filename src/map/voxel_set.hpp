// A set of packed voxel keys for one scan: open addressing, linear probing. One per
// worker, reused scan after scan; std::unordered_set's node per insert is what made ray
// insertion slow, and most rays of a scan revisit the voxels near the sensor.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

namespace vola::map::detail {

class VoxelSet {
 public:
  // Never a packed key: OccupancyMap::pack uses the low 63 bits only.
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};

  VoxelSet() { slots_.assign(1024, kEmpty); }

  // True when the key was not there yet.
  bool insert(std::uint64_t key) {
    if ((size_ + 1) * 2 > slots_.size()) grow();
    return place(slots_, key);
  }
  bool contains(std::uint64_t key) const noexcept {
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t s = hash(key) & mask;; s = (s + 1) & mask) {
      if (slots_[s] == key) return true;
      if (slots_[s] == kEmpty) return false;
    }
  }
  std::size_t size() const noexcept { return size_; }
  void clear() noexcept {
    if (size_ == 0) return;
    std::fill(slots_.begin(), slots_.end(), kEmpty);
    size_ = 0;
  }
  template <class F>
  void for_each(F&& f) const {
    for (const std::uint64_t key : slots_)
      if (key != kEmpty) f(key);
  }

 private:
  // splitmix64's finalizer: packed keys differ in a few middle bits only.
  static std::size_t hash(std::uint64_t x) noexcept {
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return static_cast<std::size_t>(x);
  }
  bool place(std::vector<std::uint64_t>& slots, std::uint64_t key) {
    const std::size_t mask = slots.size() - 1;
    for (std::size_t s = hash(key) & mask;; s = (s + 1) & mask) {
      if (slots[s] == key) return false;
      if (slots[s] == kEmpty) {
        slots[s] = key;
        ++size_;
        return true;
      }
    }
  }
  void grow() {
    std::vector<std::uint64_t> bigger(slots_.size() * 2, kEmpty);
    size_ = 0;
    for (const std::uint64_t key : slots_)
      if (key != kEmpty) place(bigger, key);
    slots_.swap(bigger);
  }

  std::vector<std::uint64_t> slots_;
  std::size_t size_ = 0;
};

}  // namespace vola::map::detail
