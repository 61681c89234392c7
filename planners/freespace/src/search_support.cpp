#include "search_support.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <queue>

#include "pullout/geometry/angle.hpp"

namespace pullout::freespace_detail {

Pose2 drive(const Pose2& from, double curvature, double distance) { return Arc(from, curvature).at(distance); }

Arc::Arc(const Pose2& from, double curvature) : Arc(from, std::cos(from.yaw), std::sin(from.yaw), curvature) {}

Arc::Arc(const Pose2& from, double cos_yaw, double sin_yaw, double curvature)
    : from_(from), cos_(cos_yaw), sin_(sin_yaw), curvature_(curvature) {}

Pose2 Arc::at(double distance) const {
  double c = 1.0;
  double s = 0.0;
  return at(distance, c, s);
}

Pose2 Arc::at(double distance, double& cos_yaw, double& sin_yaw) const {
  if (std::abs(curvature_) < 1e-12) {
    cos_yaw = cos_;
    sin_yaw = sin_;
    return {from_.x + distance * cos_, from_.y + distance * sin_, from_.yaw};
  }
  const double yaw = from_.yaw + curvature_ * distance;
  cos_yaw = std::cos(yaw);
  sin_yaw = std::sin(yaw);
  const double r = 1.0 / curvature_;
  return {from_.x + r * (sin_yaw - sin_), from_.y + r * (cos_ - cos_yaw), yaw};
}

namespace {

// [rad] heading change covered by one hull test: the hulls then lie within ~1 cm of the sweep
constexpr double kMaxSweepTurn = 0.06;
constexpr double kSweepSafety = 1e-6;  // [m] added to the sagitta: rounding only

// True when the motion over [from, to] (0 <= from <= to, metres along the arc in the direction
// `sign`) is free: hull tests of consecutive poses at most kMaxSweepTurn apart in heading, each
// grown by the sagitta of that turn (GridCollisionChecker::sweep_collides).
bool sweep_free(const GridCollisionChecker& checker, const Arc& arc, double sign, double from, double to) {
  const double turn = std::abs(arc.curvature()) * (to - from);
  const int pieces = std::max(1, static_cast<int>(std::ceil(turn / kMaxSweepTurn)));
  const double margin = checker.sweep_margin(arc.curvature(), turn / pieces) + kSweepSafety;
  // Each pose's cos and sin of its heading from Arc::at (the same values the checker would compute
  // from its yaw), and each inner pose shared by two hull tests: one sincos per pose, not four.
  double c0 = 1.0;
  double s0 = 0.0;
  Pose2 previous = arc.at(sign * from, c0, s0);
  for (int i = 1; i <= pieces; ++i) {
    double c1 = 1.0;
    double s1 = 0.0;
    const Pose2 next = arc.at(sign * (from + (to - from) * i / pieces), c1, s1);
    if (checker.sweep_collides(previous, c0, s0, next, c1, s1, margin)) return false;
    previous = next;
    c0 = c1;
    s0 = s1;
  }
  return true;
}

// arc_free after its end test passed with end_clearance.
bool sweep_to_free_end(const GridCollisionChecker& checker, const Arc& arc, double start_clearance, double distance,
                       double end_clearance) {
  const double total = std::abs(distance);
  const double sign = distance < 0.0 ? -1.0 : 1.0;
  const double factor = checker.sweep_factor(arc.curvature());
  const double covered = start_clearance / factor;              // [0, covered] is known free
  const double uncovered_end = total - end_clearance / factor;  // so is [uncovered_end, total]
  if (covered >= uncovered_end) return true;
  return sweep_free(checker, arc, sign, std::max(0.0, covered), std::min(total, uncovered_end));
}

}  // namespace

bool arc_free(const GridCollisionChecker& checker, const Arc& arc, double start_clearance, double distance,
              double& end_clearance) {
  Pose2 end;
  return arc_free(checker, arc, start_clearance, distance, end_clearance, end);
}

bool arc_free(const GridCollisionChecker& checker, const Arc& arc, double start_clearance, double distance,
              double& end_clearance, Pose2& end) {
  double c = 1.0;
  double sn = 0.0;
  // The end first: where the search stops, tested exactly (and the likeliest to collide).
  end = arc.at(distance, c, sn);
  if (checker.collides(end, c, sn, end_clearance)) return false;
  return sweep_to_free_end(checker, arc, start_clearance, distance, end_clearance);
}

double free_prefix(const GridCollisionChecker& checker, const Arc& arc, double start_clearance, double distance,
                   double min_length) {
  const double total = std::abs(distance);
  const double sign = distance < 0.0 ? -1.0 : 1.0;
  const double factor = checker.sweep_factor(arc.curvature());
  // Exact samples a cell apart (of the footprint's fastest point) up to the first collision: the
  // motion gets no farther than the last free one. Cheap where it matters: a pose at contact
  // fails its first samples.
  const double step = checker.costmap().resolution() / factor;
  double c = 1.0;
  double sn = 0.0;
  double last_free = 0.0;  // the start is free
  double s = std::max(min_length, start_clearance / factor);
  double clearance = 0.0;
  double last_clearance = 0.0;
  while (true) {
    const double at = std::min(s, total);
    const Pose2 pose = arc.at(sign * at, c, sn);  // (before the call: it sets c and sn)
    if (checker.collides(pose, c, sn, clearance)) break;
    last_free = at;
    last_clearance = clearance;
    if (at >= total) break;
    s = at + step + clearance / factor;
  }
  if (last_free < min_length) return 0.0;
  // The end pose of the motion to last_free was just tested free (the same pose: arc_free would
  // compute it from the same distance): its sweep is all that is left to test.
  if (sweep_to_free_end(checker, arc, start_clearance, sign * last_free, last_clearance)) return last_free;
  double end_clearance = 0.0;
  // The sweep to it touches: bisection for the longest free prefix (free at lo, not at hi).
  double lo = min_length;
  if (!arc_free(checker, arc, start_clearance, sign * lo, end_clearance)) return 0.0;
  double hi = last_free;
  constexpr int kBisections = 5;
  for (int i = 0; i < kBisections; ++i) {
    const double mid = 0.5 * (lo + hi);
    (arc_free(checker, arc, start_clearance, sign * mid, end_clearance) ? lo : hi) = mid;
  }
  return lo;
}

bool arc_samples_free(const GridCollisionChecker& checker, const Pose2& from, double curvature, double distance,
                      double spacing) {
  const int n = std::max(1, static_cast<int>(std::ceil(std::abs(distance) / spacing)));
  // One arc for all samples, and each sample's cos and sin of its heading from it (the values
  // the checker would compute from the yaw): one sincos per sample instead of three.
  const Arc arc(from, curvature);
  for (int i = n; i >= 1; --i) {  // the end first: it is the likeliest to collide
    double c = 1.0;
    double sn = 0.0;
    double bound = 0.0;
    const Pose2 pose = arc.at(distance * i / n, c, sn);
    if (checker.collides(pose, c, sn, bound)) return false;
  }
  return true;
}

ObstacleHeuristic::ObstacleHeuristic(const Costmap& costmap, const ObstacleHeuristicConfig& config, const Pose2& goal,
                                     const Pose2& toward)
    : costmap_(costmap), config_(config) {
  factor_ = std::max(1, static_cast<int>(std::round(config.cell_size / costmap.resolution())));
  cell_size_ = factor_ * costmap.resolution();
  width_ = (costmap.width() + factor_ - 1) / factor_;
  height_ = (costmap.height() + factor_ - 1) / factor_;
  const std::size_t n = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  distance_.assign(n, std::numeric_limits<float>::infinity());
  rate_.assign(n, std::numeric_limits<float>::quiet_NaN());
  parent_.assign(n, -1);
  // A reach [cells] that proves room >= turning_room: reach cells >= turning_room, with a margin
  // for the float rounding of the distances. -1 (no shortcut) when half_width is not below
  // turning_room (the shortcut would then say nothing about blocking).
  const double reach_cells = std::ceil((config.turning_room + 1e-4) / costmap.resolution());
  if (config.half_width < config.turning_room && reach_cells >= 0.0 && reach_cells < 1e6) {
    open_reach_ = static_cast<int>(reach_cells);
  }
  // The rooms from distances capped a cell beyond the larger of turning_room and half_width: a
  // room beyond the cap has room to turn (rate 1) and is not blocked, whatever its exact value.
  const double cap_cells = std::ceil(std::max(config.turning_room, config.half_width) / costmap.resolution()) + 1.0;
  if (cap_cells >= 1.0 && cap_cells <= DistanceField::kMaxCap &&
      factor_ * kRoomTile <= DistanceField::kMaxCappedCells) {
    room_cap_ = static_cast<int>(cap_cells);
    room_tiles_per_row_ = (width_ + kRoomTile - 1) / kRoomTile;
    room2_.assign(n, 0);
    room_tile_ready_.assign(static_cast<std::size_t>(room_tiles_per_row_) * static_cast<std::size_t>(height_), 0);
  }
  int ti = 0;
  int tj = 0;
  costmap.cell_of({toward.x, toward.y}, ti, tj);
  toward_x_ = std::clamp(ti, 0, costmap.width() - 1) / factor_;
  toward_y_ = std::clamp(tj, 0, costmap.height() - 1) / factor_;
  int gi = 0;
  int gj = 0;
  costmap.cell_of({goal.x, goal.y}, gi, gj);
  if (!costmap.inside(gi, gj)) return;
  const std::int32_t start = (gj / factor_) * width_ + (gi / factor_);
  distance_[static_cast<std::size_t>(start)] = 0.0F;
  open_.push({estimate(start), start});
}

float ObstacleHeuristic::estimate(std::int32_t c) const {
  // The shortest 8-connected path between the cell centres on an empty grid (the octile
  // distance: diagonal steps, then straight ones), less 1 % so that float rounding cannot make it
  // overestimate a path of edges (each at least its length: every rate is at least 1). It is the
  // least any path of edges can cost, and a metric (so consistent); up to 8 % above the straight
  // line it replaced, it settles fewer cells (the distances are the same).
  const std::int32_t row = c / width_;  // integer division: the cell's row
  const std::int32_t col = c % width_;
  const auto dx = static_cast<float>(std::abs(col - toward_x_));
  const auto dy = static_cast<float>(std::abs(row - toward_y_));
  return 0.99F * static_cast<float>(cell_size_) * (std::max(dx, dy) + 0.41421356F * std::min(dx, dy));
}

float ObstacleHeuristic::rate(std::int32_t c) {
  float& r = rate_[static_cast<std::size_t>(c)];
  if (!std::isnan(r)) return r;
  // A costmap cell is surely infeasible for the rear axle when even the most favourable point in
  // it is closer than half_width to an obstacle (centre distance + half a diagonal each way); the
  // coarse cell is blocked when all of its cells are. Its room: the largest obstacle distance.
  const double slack = std::sqrt(2.0) * costmap_.resolution();
  const int i0 = (c % width_) * factor_;
  const int j0 = (c / width_) * factor_;
  const int i1 = std::min(costmap_.width(), i0 + factor_);
  const int j1 = std::min(costmap_.height(), j0 + factor_);
  bool blocked = true;
  double room = 0.0;
  if (room_cap_ >= 0) {
    // The largest squared distance of the cell's costmap cells, rounded as the distance field
    // rounds each (a monotone rounding: the largest rounded is the rounded largest): the same
    // room and verdict as the scan below. It is exact up to the cap, and beyond it the rate is 1
    // and the cell not blocked either way. A free costmap cell lies at least a cell from an
    // occupied one: 0 means that all of them are occupied (blocked, as the scan finds).
    const std::int32_t tile = (c / width_) * room_tiles_per_row_ + (c % width_) / kRoomTile;
    if (room_tile_ready_[static_cast<std::size_t>(tile)] == 0) fill_room_tile(tile);
    const std::int16_t m = room2_[static_cast<std::size_t>(c)];
    room = static_cast<float>(std::sqrt(static_cast<double>(m)) * costmap_.resolution());
    blocked = m == 0 || room + slack < config_.half_width;
  } else {
    // (A cap too large for the brute force's 16 bits: a turning room of hundreds of cells.) Where
    // a costmap cell's box of open_reach_ cells each way holds no occupied cell (the border counts
    // as one), its nearest occupied cell centre lies more than open_reach_ cells away, so its room
    // is at least turning_room (see the constructor) and it is not blocked either (half_width <
    // turning_room): rate 1 without the distance transform. The centre and the four corners are
    // tried, then the cells' distances scanned.
    if (open_reach_ >= 0) {
      const int xs[5] = {(i0 + i1 - 1) / 2, i0, i1 - 1, i0, i1 - 1};
      const int ys[5] = {(j0 + j1 - 1) / 2, j0, j0, j1 - 1, j1 - 1};
      for (int k = 0; k < 5; ++k) {
        if (costmap_.occupied_in_box(xs[k] - open_reach_, ys[k] - open_reach_, xs[k] + open_reach_,
                                     ys[k] + open_reach_) == 0) {
          r = 1.0F;
          return r;
        }
      }
    }
    for (int j = j0; j < j1; ++j) {
      for (int i = i0; i < i1; ++i) {
        if (costmap_.occupied(i, j)) continue;
        const double d = costmap_.centre_distance(i, j);
        room = std::max(room, d);
        if (d + slack >= config_.half_width) blocked = false;
      }
    }
  }
  const double narrowness = std::max(0.0, 1.0 - room / config_.turning_room);
  r = blocked ? std::numeric_limits<float>::infinity() : static_cast<float>(1.0 + config_.narrow_penalty * narrowness);
  return r;
}

void ObstacleHeuristic::fill_room_tile(std::int32_t tile) {
  room_tile_ready_[static_cast<std::size_t>(tile)] = 1;
  const std::int32_t row = tile / room_tiles_per_row_;  // integer division: the tile's coarse row
  const std::int32_t first = (tile % room_tiles_per_row_) * kRoomTile;
  const std::int32_t last = std::min(width_, first + kRoomTile);
  const int i0 = first * factor_;
  const int i1 = std::min(costmap_.width(), last * factor_);
  const int j0 = row * factor_;
  const int j1 = std::min(costmap_.height(), j0 + factor_);
  std::array<std::int16_t, DistanceField::kMaxCappedCells> d2;
  std::int16_t* room = room2_.data() + static_cast<std::size_t>(row) * static_cast<std::size_t>(width_);
  for (int j = j0; j < j1; ++j) {
    costmap_.capped_squared_distances(j, i0, i1, room_cap_, d2.data());
    const std::int16_t* d = d2.data();
    for (std::int32_t x = first; x < last; ++x) {
      const int cells = std::min(factor_, i1 - x * factor_);  // (the grid's last coarse column may be partial)
      std::int16_t& r = room[x];
      for (int k = 0; k < cells; ++k) r = std::max(r, d[k]);
      d += cells;
    }
  }
}

float ObstacleHeuristic::settle(std::int32_t c) {
  // A cell's distance is final once nothing left on the open list can lower it: every open entry's
  // distance plus its (consistent) estimate is at least the cell's distance plus its own.
  const float straight = static_cast<float>(cell_size_);
  const float diagonal = static_cast<float>(cell_size_ * std::sqrt(2.0));
  constexpr int kDx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  constexpr std::size_t kStopCheckInterval = 1024;
  const float own_estimate = estimate(c);
  while (!open_.empty() && open_.top().first < distance_[static_cast<std::size_t>(c)] + own_estimate) {
    if (stopped_ != StopReason::kNone) break;
    if (stop_ != nullptr && ++settled_ % kStopCheckInterval == 0 && (stopped_ = stop_->check()) != StopReason::kNone) {
      break;
    }
    const auto [f, idx] = open_.top();
    open_.pop();
    const float d = distance_[static_cast<std::size_t>(idx)];
    if (f > d + estimate(idx)) continue;  // superseded by a shorter distance
    const float own = rate(idx);
    const int x = idx % width_;
    const int y = idx / width_;
    for (int k = 0; k < 8; ++k) {
      const int nx = x + kDx[k];
      const int ny = y + kDy[k];
      if (nx < 0 || ny < 0 || nx >= width_ || ny >= height_) continue;
      const std::int32_t nidx = ny * width_ + nx;
      const float next = rate(nidx);
      if (std::isinf(next)) continue;
      // An edge costs its length at the mean of its two cells' rates (the goal's own cell may be
      // "blocked" for the disc test: it then counts at the neighbour's rate).
      const float mean = std::isinf(own) ? next : 0.5F * (own + next);
      const float nd = d + (k < 4 ? straight : diagonal) * mean;
      if (nd < distance_[static_cast<std::size_t>(nidx)]) {
        distance_[static_cast<std::size_t>(nidx)] = nd;
        parent_[static_cast<std::size_t>(nidx)] = idx;
        open_.push({nd + estimate(nidx), nidx});
      }
    }
  }
  return distance_[static_cast<std::size_t>(c)];
}

double ObstacleHeuristic::distance(const Pose2& p) {
  int i = 0;
  int j = 0;
  costmap_.cell_of({p.x, p.y}, i, j);
  if (!costmap_.inside(i, j)) return std::numeric_limits<double>::infinity();
  // Blocked cells are never reached (except the goal's own): no need to run the search for them.
  const auto at = [this](int x, int y) {
    const std::int32_t c = y * width_ + x;
    if (std::isinf(rate(c)) && distance_[static_cast<std::size_t>(c)] != 0.0F) {
      return std::numeric_limits<double>::infinity();
    }
    return static_cast<double>(settle(c));
  };
  const double own = at(i / factor_, j / factor_);
  if (!std::isfinite(own)) return own;
  // Bilinear between the four nearest cell centres, so that the value changes smoothly with the
  // pose: a step of a whole cell's worth at cell borders would drown the cost differences of
  // the primitives (a quarter metre and less) and let the search spread sideways.
  const Vec2 g = costmap_.to_grid({p.x, p.y}) / static_cast<double>(factor_) - Vec2(0.5, 0.5);
  const int x0 = std::clamp(static_cast<int>(std::floor(g.x())), 0, width_ - 2);
  const int y0 = std::clamp(static_cast<int>(std::floor(g.y())), 0, height_ - 2);
  if (width_ < 2 || height_ < 2) return own;
  const double tx = std::clamp(g.x() - x0, 0.0, 1.0);
  const double ty = std::clamp(g.y() - y0, 0.0, 1.0);
  const double d00 = at(x0, y0);
  const double d10 = at(x0 + 1, y0);
  const double d01 = at(x0, y0 + 1);
  const double d11 = at(x0 + 1, y0 + 1);
  if (!std::isfinite(d00) || !std::isfinite(d10) || !std::isfinite(d01) || !std::isfinite(d11)) return own;
  return (1.0 - ty) * ((1.0 - tx) * d00 + tx * d10) + ty * ((1.0 - tx) * d01 + tx * d11);
}

ObstacleHeuristic::Way ObstacleHeuristic::way(const Pose2& p) {
  int i = 0;
  int j = 0;
  costmap_.cell_of({p.x, p.y}, i, j);
  Way w;
  if (!costmap_.inside(i, j)) return w;
  const std::int32_t c = (j / factor_) * width_ + (i / factor_);
  if (!std::isfinite(settle(c))) return w;  // (settled already when distance(p) came first)
  if (corner_.empty()) {
    corner_.assign(distance_.size(), -2);
    turning_.assign(distance_.size(), 0.0F);
  }
  const auto k = static_cast<std::size_t>(c);
  if (corner_[k] == -2) fill_way(c);
  const std::int32_t corner = corner_[k];
  if (corner == c) return w;                 // the goal's cell
  const std::int32_t row = corner / width_;  // integer division: the corner cell's row
  const std::int32_t col = corner % width_;
  const Vec2 to =
      costmap_.to_map({(static_cast<double>(col) + 0.5) * factor_, (static_cast<double>(row) + 0.5) * factor_});
  w.yaw = std::atan2(to.y() - p.y, to.x() - p.x);
  w.turning = turning_[k];
  w.known = true;
  w.room = rate(c) <= 1.0F;
  return w;
}

bool ObstacleHeuristic::visible(std::int32_t a, std::int32_t b) {
  // Samples along the line a whole cell apart on its longer axis, and the cells on both sides of
  // each step across the shorter one, so that the line cannot slip between two blocked cells.
  const int ax = a % width_;
  const int ay = a / width_;
  const int dx = b % width_ - ax;
  const int dy = b / width_ - ay;
  const int n = std::max(std::abs(dx), std::abs(dy));
  int last_x = ax;
  int last_y = ay;
  for (int s = 1; s <= n; ++s) {
    const int x = ax + static_cast<int>(std::lround(static_cast<double>(dx) * s / n));
    const int y = ay + static_cast<int>(std::lround(static_cast<double>(dy) * s / n));
    if (std::isinf(rate(y * width_ + x))) return false;
    if (x != last_x && y != last_y &&
        (std::isinf(rate(last_y * width_ + x)) || std::isinf(rate(y * width_ + last_x)))) {
      return false;
    }
    last_x = x;
    last_y = y;
  }
  return true;
}

void ObstacleHeuristic::fill_way(std::int32_t c) {
  // The cells ahead whose way is not known yet, then each from the goal's side: a cell's corner
  // comes from the next cell's. Every cell ahead was taken off the open list before the cell it
  // led to, so its distance and its own next cell are final.
  chain_.clear();
  for (std::int32_t x = c; x >= 0 && corner_[static_cast<std::size_t>(x)] == -2;
       x = parent_[static_cast<std::size_t>(x)]) {
    chain_.push_back(x);
  }
  const auto centre = [this](std::int32_t x) { return Vec2(x % width_, x / width_); };
  for (auto it = chain_.rbegin(); it != chain_.rend(); ++it) {
    const std::int32_t x = *it;
    const auto k = static_cast<std::size_t>(x);
    const std::int32_t next = parent_[k];
    if (next < 0) {  // the goal's cell (the only settled cell without a next one)
      corner_[k] = x;
      continue;
    }
    const std::int32_t beyond = corner_[static_cast<std::size_t>(next)];
    const std::int32_t corner = beyond != next && visible(x, beyond) ? beyond : next;
    corner_[k] = corner;
    const std::int32_t after = corner_[static_cast<std::size_t>(corner)];
    if (after == corner) {  // straight to the goal's cell
      turning_[k] = 0.0F;
      continue;
    }
    const Vec2 in = centre(corner) - centre(x);
    const Vec2 out = centre(after) - centre(corner);
    const double turn = std::abs(std::atan2(in.x() * out.y() - in.y() * out.x(), in.dot(out)));
    turning_[k] = turning_[static_cast<std::size_t>(corner)] + static_cast<float>(turn);
  }
}

double turning_ahead(const ObstacleHeuristic::Way& way, double travel_yaw) {
  return std::abs(normalize_angle(travel_yaw - way.yaw)) + way.turning;
}

NodeTable::NodeTable() {
  keys_.assign(1u << 12, kEmptyKey);
  values_.assign(keys_.size(), -1);
  mask_ = keys_.size() - 1;
  shift_ = 64 - 12;
}

std::int32_t* NodeTable::find_or_insert(std::uint64_t key) {
  if (2 * (size_ + 1) > keys_.size()) grow();
  // Fibonacci hashing: the product's top bits, which every bit of the key reaches. (The middle
  // bits taken before depend on none of the key's column bits, 41 and up: the cells of a row of
  // the lattice with the same heading all landed in one run of slots, and the linear probing
  // walked it, a seventh of a long search's time.)
  std::uint64_t h = (key * 0x9E3779B97F4A7C15ULL) >> shift_;
  while (true) {
    const std::size_t i = static_cast<std::size_t>(h & mask_);
    if (keys_[i] == key) return &values_[i];
    if (keys_[i] == kEmptyKey) {
      keys_[i] = key;
      ++size_;
      return &values_[i];
    }
    ++h;
  }
}

void NodeTable::grow() {
  std::vector<std::uint64_t> old_keys(keys_.size() * 2, kEmptyKey);
  std::vector<std::int32_t> old_values(keys_.size() * 2, -1);
  old_keys.swap(keys_);
  old_values.swap(values_);
  mask_ = keys_.size() - 1;
  --shift_;
  size_ = 0;
  for (std::size_t i = 0; i < old_keys.size(); ++i) {
    if (old_keys[i] != kEmptyKey) *find_or_insert(old_keys[i]) = old_values[i];
  }
}

}  // namespace pullout::freespace_detail
