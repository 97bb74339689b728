#include "vola/raycast/clearance_field.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "vola/error.hpp"

namespace vola::raycast {

namespace {

// The squared gap along one axis between a cell's centre and the cube of the voxel
// `d` cells away: exact in double (quarter integers).
double gap2(int d) {
  if (d == 0) return 0.0;
  const double g = std::abs(d) - 0.5;
  return g * g;
}

std::int64_t floor_div(std::int64_t a, std::int64_t b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

}  // namespace

ClearanceField::ClearanceField(const Tree& obstacles, double radius, const Tree* known, bool solid_ground)
    : side_(obstacles.side()), known_mode_(known != nullptr) {
  if (!(radius >= 0.0) || !std::isfinite(radius)) throw InvalidArgument("plan: the radius must be finite and >= 0");
  const double r2 = radius * radius;
  reach_ = 0;
  while (gap2(reach_ + 1) <= r2) {
    ++reach_;
    if (reach_ > kMaxReach)
      throw InvalidArgument("plan: a radius of " + std::to_string(radius) + " cells reaches more than " +
                            std::to_string(kMaxReach) + " cells: plan on a coarser level (cells 4 times larger)");
  }
  const int n = 2 * reach_ + 1;
  reach_x_.assign(static_cast<std::size_t>(n * n), -1);
  for (int dz = -reach_; dz <= reach_; ++dz)
    for (int dy = -reach_; dy <= reach_; ++dy)
      for (int dx = 0; dx <= reach_; ++dx)
        if (gap2(dx) + gap2(dy) + gap2(dz) <= r2) reach_x_[static_cast<std::size_t>((dz + reach_) * n + dy + reach_)] = dx;

  // The leaf words by brick, one pass over each tree's leaf blocks in storage order: the
  // blocks of a brick (a level depth-3 cell) are consecutive there, in the order of their
  // index in the brick, so each brick's words are appended as one run.
  const auto store = [&](const Tree& tree, bool is_known) {
    std::uint64_t current = ~std::uint64_t{0};
    tree.for_each_block(tree.depth() - 1, [&](std::size_t, std::uint64_t word, std::uint32_t ox, std::uint32_t oy,
                                             std::uint32_t oz) {
      const std::uint64_t key = brick_key(ox / kBrick, oy / kBrick, oz / kBrick);
      StoredWords& run = is_known ? stored_[key].known : stored_[key].occupied;
      const unsigned block = (ox / 4 % 4) + 4 * (oy / 4 % 4) + 16 * (oz / 4 % 4);
      if (key != current) {
        if (run.present) throw Error("clearance field: a brick's leaf blocks are not consecutive");
        run.first = words_.size();
        current = key;
      }
      run.present |= std::uint64_t{1} << block;
      words_.push_back(word);
    });
  };
  store(obstacles, false);
  if (known) store(*known, true);
  if (solid_ground && !obstacles.empty()) find_ground(obstacles);
  rows_.emplace_back();
  rows_.back().fill(0xFFFF);
  slot_all_free_.push_back(1);
}

void ClearanceField::find_ground(const Tree& obstacles) {
  constexpr std::int64_t kWindow = 2;  // columns on each side
  std::int64_t lo[2] = {side_, side_}, hi[2] = {0, 0};
  obstacles.for_each_block(obstacles.depth() - 1, [&](std::size_t, std::uint64_t, std::uint32_t ox, std::uint32_t oy,
                                                      std::uint32_t) {
    lo[0] = std::min<std::int64_t>(lo[0], ox), lo[1] = std::min<std::int64_t>(lo[1], oy);
    hi[0] = std::max<std::int64_t>(hi[0], ox + 4), hi[1] = std::max<std::int64_t>(hi[1], oy + 4);
  });
  ground_x0_ = std::max<std::int64_t>(0, lo[0] - kWindow);
  ground_y0_ = std::max<std::int64_t>(0, lo[1] - kWindow);
  ground_nx_ = std::min<std::int64_t>(side_, hi[0] + kWindow) - ground_x0_;
  ground_ny_ = std::min<std::int64_t>(side_, hi[1] + kWindow) - ground_y0_;
  constexpr std::int32_t kNone = std::numeric_limits<std::int32_t>::max();
  std::vector<std::int32_t> lowest(static_cast<std::size_t>(ground_nx_ * ground_ny_), kNone);
  obstacles.for_each_block(obstacles.depth() - 1, [&](std::size_t, std::uint64_t word, std::uint32_t ox,
                                                      std::uint32_t oy, std::uint32_t oz) {
    while (word) {
      const unsigned b = static_cast<unsigned>(std::countr_zero(word));
      word &= word - 1;
      const auto i = static_cast<std::size_t>((oy + ((b >> 2) & 3u) - ground_y0_) * ground_nx_ + (ox + (b & 3u) - ground_x0_));
      lowest[i] = std::min(lowest[i], static_cast<std::int32_t>(oz + (b >> 4)));
    }
  });
  // The smallest within the window: along x, then along y.
  std::vector<std::int32_t> along_x(lowest.size(), kNone);
  for (std::int64_t y = 0; y < ground_ny_; ++y)
    for (std::int64_t x = 0; x < ground_nx_; ++x)
      for (std::int64_t d = std::max<std::int64_t>(0, x - kWindow); d <= std::min(ground_nx_ - 1, x + kWindow); ++d)
        along_x[static_cast<std::size_t>(y * ground_nx_ + x)] =
            std::min(along_x[static_cast<std::size_t>(y * ground_nx_ + x)], lowest[static_cast<std::size_t>(y * ground_nx_ + d)]);
  ground_.assign(lowest.size(), kNone);
  for (std::int64_t y = 0; y < ground_ny_; ++y)
    for (std::int64_t d = std::max<std::int64_t>(0, y - kWindow); d <= std::min(ground_ny_ - 1, y + kWindow); ++d)
      for (std::int64_t x = 0; x < ground_nx_; ++x)
        ground_[static_cast<std::size_t>(y * ground_nx_ + x)] =
            std::min(ground_[static_cast<std::size_t>(y * ground_nx_ + x)], along_x[static_cast<std::size_t>(d * ground_nx_ + x)]);
  // Per brick column, the highest ground of the columns within reach (-1: none): a brick
  // whose cells all lie above it plus the reach needs no ground bits.
  const std::int64_t bricks = bricks_per_side();
  ground_by_brick_.assign(static_cast<std::size_t>(bricks * bricks), -1);
  for (std::int64_t y = 0; y < ground_ny_; ++y)
    for (std::int64_t x = 0; x < ground_nx_; ++x) {
      const std::int32_t g = ground_[static_cast<std::size_t>(y * ground_nx_ + x)];
      if (g == kNone) continue;
      const std::int64_t gx = x + ground_x0_, gy = y + ground_y0_;
      for (std::int64_t by = std::max<std::int64_t>(0, (gy - reach_) / kBrick); by <= std::min(bricks - 1, (gy + reach_) / kBrick); ++by)
        for (std::int64_t bx = std::max<std::int64_t>(0, (gx - reach_) / kBrick); bx <= std::min(bricks - 1, (gx + reach_) / kBrick); ++bx) {
          auto& top = ground_by_brick_[static_cast<std::size_t>(by * bricks + bx)];
          top = std::max(top, g);
        }
    }
}

std::int32_t ClearanceField::ground_at(std::int64_t x, std::int64_t y) const noexcept {
  x -= ground_x0_;
  y -= ground_y0_;
  if (x < 0 || y < 0 || x >= ground_nx_ || y >= ground_ny_) return std::numeric_limits<std::int32_t>::max();
  return ground_[static_cast<std::size_t>(y * ground_nx_ + x)];
}

bool ClearanceField::near_obstacle(std::int64_t bx, std::int64_t by, std::int64_t bz) const noexcept {
  if (known_mode_ || side_ < kBrick) return true;  // unknown space (or cells off the grid) is everywhere else
  if (!ground_by_brick_.empty() && bz * kBrick - reach_ < ground_by_brick_[static_cast<std::size_t>(by * bricks_per_side() + bx)])
    return true;  // under the ground, or within reach of it
  const std::int64_t lo[3] = {bx * kBrick - reach_, by * kBrick - reach_, bz * kBrick - reach_};
  for (std::int64_t z = floor_div(lo[2], kBrick); z <= floor_div(lo[2] + kBrick + 2 * reach_ - 1, kBrick); ++z)
    for (std::int64_t y = floor_div(lo[1], kBrick); y <= floor_div(lo[1] + kBrick + 2 * reach_ - 1, kBrick); ++y)
      for (std::int64_t x = floor_div(lo[0], kBrick); x <= floor_div(lo[0] + kBrick + 2 * reach_ - 1, kBrick); ++x)
        if (x >= 0 && y >= 0 && z >= 0 && stored_.count(brick_key(x, y, z))) return true;
  return false;
}

bool ClearanceField::compute(std::int64_t bx, std::int64_t by, std::int64_t bz, std::uint16_t* out) {
  ++computed_;
  const int R = reach_, W = kBrick + 2 * R;
  const std::int64_t lo[3] = {bx * kBrick - R, by * kBrick - R, bz * kBrick - R};
  const std::int64_t blocks = side_ / 4;
  gathered_.assign(static_cast<std::size_t>(W * W), 0);
  // Gather: each 4x4x4 obstacle word gives 16 nibbles, one per row it crosses.
  for (std::int64_t cz = floor_div(lo[2], kBrick); cz <= floor_div(lo[2] + W - 1, kBrick); ++cz)
    for (std::int64_t cy = floor_div(lo[1], kBrick); cy <= floor_div(lo[1] + W - 1, kBrick); ++cy)
      for (std::int64_t cx = floor_div(lo[0], kBrick); cx <= floor_div(lo[0] + W - 1, kBrick); ++cx) {
        const StoredBrick* stored = nullptr;
        if (cx >= 0 && cy >= 0 && cz >= 0) {
          const auto found = stored_.find(brick_key(cx, cy, cz));
          if (found != stored_.end()) stored = &found->second;
        }
        if (!stored && !known_mode_) continue;
        for (int sub = 0; sub < 64; ++sub) {
          const std::int64_t X = cx * 4 + (sub & 3), Y = cy * 4 + ((sub >> 2) & 3), Z = cz * 4 + (sub >> 4);
          const std::int64_t x0 = X * 4 - lo[0], y0 = Y * 4 - lo[1], z0 = Z * 4 - lo[2];
          if (x0 <= -4 || x0 >= W || y0 <= -4 || y0 >= W || z0 <= -4 || z0 >= W) continue;
          std::uint64_t word = 0;
          const bool on_grid = X >= 0 && Y >= 0 && Z >= 0 && X < blocks && Y < blocks && Z < blocks;
          if (!on_grid) word = known_mode_ ? ~std::uint64_t{0} : 0;
          else if (stored) word = word_of(stored->occupied, sub) | (known_mode_ ? ~word_of(stored->known, sub) : 0);
          else word = ~std::uint64_t{0};  // known mode, a brick with no known voxel
          if (!word) continue;
          for (int sz = 0; sz < 4; ++sz) {
            const std::int64_t z = z0 + sz;
            if (z < 0 || z >= W) continue;
            for (int sy = 0; sy < 4; ++sy) {
              const std::int64_t y = y0 + sy;
              if (y < 0 || y >= W) continue;
              const std::uint64_t nibble = (word >> (4 * sy + 16 * sz)) & 15u;
              if (!nibble) continue;
              gathered_[static_cast<std::size_t>(z * W + y)] |= x0 >= 0 ? nibble << x0 : nibble >> -x0;
            }
          }
        }
      }
  // Under the ground: the cells of each row below its columns' ground.
  if (!ground_by_brick_.empty() && bz * kBrick - R < ground_by_brick_[static_cast<std::size_t>(by * bricks_per_side() + bx)])
    for (int z = 0; z < W; ++z)
      for (int y = 0; y < W; ++y) {
        std::uint64_t& row = gathered_[static_cast<std::size_t>(z * W + y)];
        for (int x = 0; x < W; ++x) {
          const std::int32_t ground = ground_at(lo[0] + x, lo[1] + y);
          if (ground != std::numeric_limits<std::int32_t>::max() && lo[2] + z < ground) row |= std::uint64_t{1} << x;
        }
      }
  // Dilate each row along x by 0..R cells, then OR the rows S names for each brick row.
  const std::size_t plane = static_cast<std::size_t>(W * W);
  dilated_.resize(plane * static_cast<std::size_t>(R + 1));
  std::copy(gathered_.begin(), gathered_.end(), dilated_.begin());
  for (int k = 1; k <= R; ++k)
    for (std::size_t i = 0; i < plane; ++i) {
      const std::uint64_t prev = dilated_[(k - 1) * plane + i];
      dilated_[k * plane + i] = prev | prev << 1 | prev >> 1;
    }
  const int n = 2 * R + 1;
  std::uint16_t x_on_grid = 0;
  for (int x = 0; x < kBrick; ++x)
    if (bx * kBrick + x < side_) x_on_grid |= static_cast<std::uint16_t>(1u << x);
  bool all_free = true;
  for (int z = 0; z < kBrick; ++z)
    for (int y = 0; y < kBrick; ++y) {
      std::uint16_t row = 0;
      if (by * kBrick + y < side_ && bz * kBrick + z < side_) {
        std::uint64_t blocked = 0;
        for (int dz = -R; dz <= R; ++dz) {
          const std::uint64_t* layer = &dilated_[static_cast<std::size_t>((z + R + dz) * W + y + R)];
          const int* kx = &reach_x_[static_cast<std::size_t>((dz + R) * n + R)];
          for (int dy = -R; dy <= R; ++dy)
            if (kx[dy] >= 0) blocked |= layer[static_cast<std::size_t>(kx[dy]) * plane + static_cast<std::size_t>(dy)];
        }
        row = static_cast<std::uint16_t>(~(blocked >> R) & x_on_grid);
      }
      out[y + kBrick * z] = row;
      all_free = all_free && row == 0xFFFF;
    }
  return all_free;
}

const std::uint16_t* ClearanceField::brick(std::int64_t bx, std::int64_t by, std::int64_t bz) {
  const std::uint64_t key = brick_key(bx, by, bz);
  if (key == last_key_) return rows_[last_slot_].data();
  std::uint32_t slot = 0;
  const auto found = rows_of_.find(key);
  if (found != rows_of_.end()) {
    slot = found->second;
  } else {
    if (near_obstacle(bx, by, bz)) {
      slot = static_cast<std::uint32_t>(rows_.size());
      rows_.emplace_back();
      slot_all_free_.push_back(compute(bx, by, bz, rows_.back().data()) ? 1 : 0);
    }
    rows_of_.emplace(key, slot);
  }
  last_key_ = key;
  last_slot_ = slot;
  return rows_[slot].data();
}

bool ClearanceField::brick_all_free(std::int64_t bx, std::int64_t by, std::int64_t bz) {
  brick(bx, by, bz);
  return slot_all_free_[last_slot_] != 0;
}

bool ClearanceField::free(std::int64_t x, std::int64_t y, std::int64_t z) {
  if (!inside(x, y, z)) return false;
  const std::uint16_t* rows = brick(x / kBrick, y / kBrick, z / kBrick);
  return (rows[(y % kBrick) + kBrick * (z % kBrick)] >> (x % kBrick)) & 1u;
}

}  // namespace vola::raycast
