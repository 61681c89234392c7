// The obstacle-aware distance of the hybrid A* (search_support.hpp), computed lazily by an A*
// towards the search's root. Oracle: a plain Dijkstra search over every coarse cell, written here,
// on rates computed from brute-force distances: the order in which the lazy search settles cells
// must not change a distance.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <random>
#include <vector>

#include "pullout/geometry/angle.hpp"
#include "search_support.hpp"

namespace pullout {
namespace {

namespace fd = freespace_detail;

constexpr double kRes = 0.1;
constexpr int kFactor = 5;  // costmap cells per coarse cell (0.5 m)

struct Map {
  int w{0};
  int h{0};
  std::vector<std::uint8_t> occ;
};

// Rooms and walls with random boxes: narrow places (rates above 1) and blocked cells.
Map random_map(std::mt19937& rng) {
  Map m{150, 100, std::vector<std::uint8_t>(150 * 100, 0)};
  std::uniform_int_distribution<int> x(0, m.w - 1), y(0, m.h - 1), side(2, 16);
  for (int k = 0; k < 12; ++k) {
    const int x0 = x(rng), y0 = y(rng), sx = side(rng), sy = side(rng);
    for (int j = y0; j < std::min(m.h, y0 + sy); ++j) {
      for (int i = x0; i < std::min(m.w, x0 + sx); ++i) m.occ[static_cast<std::size_t>(j) * m.w + i] = 1;
    }
  }
  return m;
}

double brute_distance(const Map& m, const std::vector<std::pair<int, int>>& occupied, int i, int j) {
  double best = std::min({i + 1, j + 1, m.w - i, m.h - j});
  for (const auto& [x, y] : occupied) best = std::min(best, std::hypot(x - i, y - j));
  return best * kRes;
}

// The documented rates of the coarse cells, from brute-force distances.
std::vector<float> oracle_rates(const Map& m, const std::vector<std::pair<int, int>>& occupied,
                                const fd::ObstacleHeuristicConfig& config) {
  const int cw = m.w / kFactor, ch = m.h / kFactor;
  std::vector<float> rate(static_cast<std::size_t>(cw) * ch);
  for (int cj = 0; cj < ch; ++cj) {
    for (int ci = 0; ci < cw; ++ci) {
      bool blocked = true;
      double room = 0.0;
      for (int j = cj * kFactor; j < (cj + 1) * kFactor; ++j) {
        for (int i = ci * kFactor; i < (ci + 1) * kFactor; ++i) {
          if (m.occ[static_cast<std::size_t>(j) * m.w + i] != 0) continue;
          const double d = brute_distance(m, occupied, i, j);
          room = std::max(room, d);
          if (d + std::sqrt(2.0) * kRes >= config.half_width) blocked = false;
        }
      }
      rate[static_cast<std::size_t>(cj) * cw + ci] =
          blocked ? std::numeric_limits<float>::infinity()
                  : static_cast<float>(1.0 + config.narrow_penalty * std::max(0.0, 1.0 - room / config.turning_room));
    }
  }
  return rate;
}

// Dijkstra from coarse cell (gx, gy) over every cell (edges: length x mean rate of the two).
std::vector<float> oracle_distances(const Map& m, const std::vector<float>& rate, int gx, int gy) {
  const int cw = m.w / kFactor, ch = m.h / kFactor;
  std::vector<float> dist(rate.size(), std::numeric_limits<float>::infinity());
  using Item = std::pair<float, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  dist[static_cast<std::size_t>(gy) * cw + gx] = 0.0F;
  open.push({0.0F, gy * cw + gx});
  while (!open.empty()) {
    const auto [d, c] = open.top();
    open.pop();
    if (d > dist[static_cast<std::size_t>(c)]) continue;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = c % cw + dx, ny = c / cw + dy;
        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= cw || ny >= ch) continue;
        const float next = rate[static_cast<std::size_t>(ny) * cw + nx];
        if (std::isinf(next)) continue;
        const float own = rate[static_cast<std::size_t>(c)];
        const float mean = std::isinf(own) ? next : 0.5F * (own + next);
        const float len = static_cast<float>(kRes * kFactor * (dx != 0 && dy != 0 ? std::sqrt(2.0) : 1.0));
        const float nd = d + len * mean;
        if (nd < dist[static_cast<std::size_t>(ny) * cw + nx]) {
          dist[static_cast<std::size_t>(ny) * cw + nx] = nd;
          open.push({nd, ny * cw + nx});
        }
      }
    }
  }
  return dist;
}

std::vector<std::pair<int, int>> occupied_cells(const Map& m) {
  std::vector<std::pair<int, int>> occupied;
  for (int y = 0; y < m.h; ++y) {
    for (int x = 0; x < m.w; ++x) {
      if (m.occ[static_cast<std::size_t>(y) * m.w + x] != 0) occupied.emplace_back(x, y);
    }
  }
  return occupied;
}

// The lazy search on map m, asked at every coarse cell centre in a random order from a root
// somewhere else, against the oracle's Dijkstra distances on `rate` (oracle_rates of m).
void expect_lazy_search_matches_dijkstra(const Map& m, const fd::ObstacleHeuristicConfig& config,
                                         const std::vector<float>& rate, std::mt19937& rng) {
  const Costmap costmap({}, kRes, m.w, m.h, m.occ);
  const int cw = m.w / kFactor, ch = m.h / kFactor;
  std::uniform_int_distribution<int> cx(0, cw - 1), cy(0, ch - 1);
  int gx = cx(rng), gy = cy(rng);
  while (std::isinf(rate[static_cast<std::size_t>(gy) * cw + gx])) {
    gx = cx(rng);
    gy = cy(rng);
  }
  const std::vector<float> dist = oracle_distances(m, rate, gx, gy);
  // (At coarse cell centres the bilinear value is the cell's own.)
  const auto centre = [&](int ci, int cj) {
    return Pose2{(ci + 0.5) * kFactor * kRes, (cj + 0.5) * kFactor * kRes, 0.0};
  };
  fd::ObstacleHeuristic heuristic(costmap, config, centre(gx, gy), centre(cx(rng), cy(rng)));
  std::vector<int> order(rate.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
  std::shuffle(order.begin(), order.end(), rng);
  int finite = 0;
  for (const int c : order) {
    const double expected = dist[static_cast<std::size_t>(c)];
    const double got = heuristic.distance(centre(c % cw, c / cw));
    if (std::isinf(expected) || std::isinf(rate[static_cast<std::size_t>(c)])) {
      EXPECT_TRUE(std::isinf(got)) << "cell " << c % cw << "," << c / cw;
      continue;
    }
    ++finite;
    // Float sums over paths of equal length may round differently: a relative 1e-5.
    ASSERT_NEAR(got, expected, 1e-5 * std::max(1.0, expected)) << "cell " << c % cw << "," << c / cw;
  }
  EXPECT_GT(finite, cw * ch / 3);  // the map is mostly connected: the test compares many cells
}

// Several turning rooms: the heuristic takes the rooms from distances capped a cell beyond the
// turning room (search_support.cpp, rate()); the oracle scans brute-force distances. Room lengths
// on, just off and between whole cells.
TEST(ObstacleHeuristic, LazySearchTowardsTheRootGivesDijkstraDistances) {
  std::mt19937 rng(13);
  constexpr double kTurningRooms[] = {1.5, 0.95, 2.25, 1.0 + 1e-9, 0.7};
  for (int trial = 0; trial < 6; ++trial) {
    const Map m = random_map(rng);
    fd::ObstacleHeuristicConfig config;
    config.half_width = 0.6;
    config.cell_size = kRes * kFactor;
    config.turning_room = trial < 2 ? 1.5 : kTurningRooms[trial - 1];
    config.narrow_penalty = 3.0;
    expect_lazy_search_matches_dijkstra(m, config, oracle_rates(m, occupied_cells(m), config), rng);
  }
}

// A turning room too long for the capped distances' 16 bits (13 m = 130 cells): the rooms are
// scanned from the distance field, and the summed-area table tells the cells with room to turn
// (no occupied cell within 131 cells: the middle of a 40 m x 30 m yard with small boxes in its
// corners).
TEST(ObstacleHeuristic, ALongTurningRoomGivesTheSameDistances) {
  std::mt19937 rng(5);
  Map m{400, 300, std::vector<std::uint8_t>(400 * 300, 0)};
  std::uniform_int_distribution<int> corner(0, 40), side(2, 6);
  for (int k = 0; k < 8; ++k) {
    const int x0 = k % 2 == 0 ? corner(rng) : m.w - 7 - corner(rng);
    const int y0 = k % 4 < 2 ? corner(rng) : m.h - 7 - corner(rng);
    const int sx = side(rng), sy = side(rng);
    for (int j = y0; j < std::min(m.h, y0 + sy); ++j) {
      for (int i = x0; i < std::min(m.w, x0 + sx); ++i) m.occ[static_cast<std::size_t>(j) * m.w + i] = 1;
    }
  }
  fd::ObstacleHeuristicConfig config;
  config.half_width = 0.6;
  config.cell_size = kRes * kFactor;
  config.turning_room = 13.0;
  config.narrow_penalty = 3.0;
  const std::vector<float> rate = oracle_rates(m, occupied_cells(m), config);
  expect_lazy_search_matches_dijkstra(m, config, rate, rng);
  // Some cells had room to turn (rate 1): the shortcut's case was compared too.
  EXPECT_GT(std::count(rate.begin(), rate.end(), 1.0F), 50);
}

// The hybrid A* asks first at its root and then around it, where the lazy search has settled the
// least: a distance answered there is final only if the search's estimate never overestimates.
// A wall with one gap between the goal and the root makes the way detour (an estimate 30 % too
// high fails here, as does the octile distance with a diagonal step charged 1.5 instead of
// sqrt 2).
TEST(ObstacleHeuristic, AnswersAroundTheRootAreFinalFromTheFirstQuery) {
  std::mt19937 rng(29);
  int compared = 0;
  for (int trial = 0; trial < 8; ++trial) {
    Map m = random_map(rng);
    std::uniform_int_distribution<int> gap_at(0, m.w - 15);
    const int gap = gap_at(rng);
    for (int y = m.h / 2; y < m.h / 2 + 3; ++y) {
      for (int x = 0; x < m.w; ++x) {
        if (x < gap || x >= gap + 12) m.occ[static_cast<std::size_t>(y) * m.w + x] = 1;
      }
    }
    const Costmap costmap({}, kRes, m.w, m.h, m.occ);
    fd::ObstacleHeuristicConfig config;
    config.half_width = 0.6;
    config.cell_size = kRes * kFactor;
    config.turning_room = 1.5;
    config.narrow_penalty = 3.0;
    const std::vector<float> rate = oracle_rates(m, occupied_cells(m), config);
    const int cw = m.w / kFactor, ch = m.h / kFactor;
    // The goal below the wall, the root above it, both in free cells.
    std::uniform_int_distribution<int> cx(0, cw - 1), below(0, ch / 2 - 2), above(ch / 2 + 2, ch - 1);
    const auto pick = [&](std::uniform_int_distribution<int>& row) {
      while (true) {
        const int x = cx(rng), y = row(rng);
        if (!std::isinf(rate[static_cast<std::size_t>(y) * cw + x])) return std::pair<int, int>{x, y};
      }
    };
    const auto [gx, gy] = pick(below);
    // Plain ints, not a structured binding: the lambda below captures them (C++17).
    const std::pair<int, int> root = pick(above);
    const int rx = root.first;
    const int ry = root.second;
    const std::vector<float> dist = oracle_distances(m, rate, gx, gy);
    const auto centre = [&](int ci, int cj) {
      return Pose2{(ci + 0.5) * kFactor * kRes, (cj + 0.5) * kFactor * kRes, 0.0};
    };
    fd::ObstacleHeuristic heuristic(costmap, config, centre(gx, gy), centre(rx, ry));
    // The root first, then the cells by their distance from it, as a search from it asks.
    std::vector<int> order(rate.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<int>(k);
    const auto ring = [&](int c) { return std::max(std::abs(c % cw - rx), std::abs(c / cw - ry)); };
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return ring(a) < ring(b); });
    for (std::size_t k = 0; k < 150; ++k) {
      const int c = order[k];
      const double expected = dist[static_cast<std::size_t>(c)];
      const double got = heuristic.distance(centre(c % cw, c / cw));
      if (std::isinf(expected) || std::isinf(rate[static_cast<std::size_t>(c)])) continue;
      ++compared;
      ASSERT_NEAR(got, expected, 1e-5 * std::max(1.0, expected))
          << "trial " << trial << " cell " << c % cw << "," << c / cw << " (query " << k << ")";
    }
  }
  EXPECT_GT(compared, 500);
}

// The way of ObstacleHeuristic::way: corridors 5 m wide on a 30 m map, the rest occupied.
struct Corridor {
  double x0, y0, x1, y1;  // [m]
};

Map corridor_map(const std::vector<Corridor>& corridors) {
  Map m{300, 300, std::vector<std::uint8_t>(300 * 300, 1)};
  for (int j = 0; j < m.h; ++j) {
    for (int i = 0; i < m.w; ++i) {
      const double x = (i + 0.5) * kRes, y = (j + 0.5) * kRes;
      for (const Corridor& c : corridors) {
        if (x >= c.x0 && x <= c.x1 && y >= c.y0 && y <= c.y1) m.occ[static_cast<std::size_t>(j) * m.w + i] = 0;
      }
    }
  }
  return m;
}

fd::ObstacleHeuristicConfig way_config() {
  fd::ObstacleHeuristicConfig config;
  config.half_width = 0.95;
  config.cell_size = kRes * kFactor;
  config.turning_room = 2.8;
  config.narrow_penalty = 3.0;
  return config;
}

// On an open map the way to the goal is a straight line whatever its slant: it points at the goal
// and turns nothing, although the 8-connected shortest paths under it are staircases whose steps
// go in one of eight directions, and ties between equally short ones may put every diagonal step
// first (a bend of up to 45 degrees that the car need not turn). Independent bound: the straight
// line from the pose to the goal (its bearing, no turn).
TEST(ObstacleHeuristic, WayOverOpenGroundPointsAtTheGoalAndDoesNotTurn) {
  Map m{300, 300, std::vector<std::uint8_t>(300 * 300, 0)};
  const Costmap costmap({}, kRes, m.w, m.h, m.occ);
  const fd::ObstacleHeuristicConfig config = way_config();
  const Pose2 goal{15.25, 15.25, 0.0};
  fd::ObstacleHeuristic heuristic(costmap, config, goal, Pose2{3.0, 4.0, 0.0});
  double worst_bearing = 0.0;
  double worst_turning = 0.0;
  int compared = 0;
  for (int cj = 4; cj < 56; cj += 3) {
    for (int ci = 4; ci < 56; ci += 3) {
      const Pose2 p{(ci + 0.5) * 0.5, (cj + 0.5) * 0.5, 0.0};
      if (std::hypot(goal.x - p.x, goal.y - p.y) < 1.0) continue;  // (the goal's own cell)
      ASSERT_TRUE(std::isfinite(heuristic.distance(p)));
      const fd::ObstacleHeuristic::Way way = heuristic.way(p);
      ASSERT_TRUE(way.known);
      // Room to turn: more than turning_room from the map's border.
      if (std::min({p.x, p.y, 30.0 - p.x, 30.0 - p.y}) > config.turning_room + 0.5) EXPECT_TRUE(way.room);
      const double bearing = std::atan2(goal.y - p.y, goal.x - p.x);
      worst_bearing = std::max(worst_bearing, std::abs(normalize_angle(way.yaw - bearing)));
      worst_turning = std::max(worst_turning, way.turning);
      ++compared;
    }
  }
  EXPECT_GT(compared, 250);
  // The way points at the centre of the goal's cell (the goal lies in it; a quarter cell off at
  // 1 m or more: 0.18 rad at most).
  EXPECT_LT(worst_bearing, 0.2);
  EXPECT_LE(worst_turning, 1e-6) << "a straight way counted as turning";
}

// Round corners: an L (one corner of 90 degrees) and a U (two). A pose on the first leg, aligned
// with the way, has the corners still to turn; one turned away has more. Independent bound: a car
// on the first leg must change its heading by at least the corners' sum to leave the last leg
// towards the goal, and the way counts that much, within the grid's rounding of the corners.
TEST(ObstacleHeuristic, WayRoundCornersCountsTheTurningStillAhead) {
  const fd::ObstacleHeuristicConfig config = way_config();
  struct Case {
    std::vector<Corridor> corridors;
    Pose2 goal;
    double corners;  // [rad]
  };
  const Case cases[] = {
      {{{1.0, 2.0, 29.0, 7.0}, {23.0, 2.0, 28.0, 29.0}}, {25.5, 27.0, kPi / 2}, kPi / 2},
      {{{1.0, 2.0, 29.0, 7.0}, {23.0, 2.0, 28.0, 28.0}, {1.0, 23.0, 28.0, 28.0}}, {3.0, 25.5, kPi}, kPi},
  };
  for (const Case& c : cases) {
    const Map m = corridor_map(c.corridors);
    const Costmap costmap({}, kRes, m.w, m.h, m.occ);
    fd::ObstacleHeuristic heuristic(costmap, config, c.goal, Pose2{3.0, 4.5, 0.0});
    for (double x = 3.0; x <= 16.0; x += 0.5) {
      const Pose2 p{x, 4.5, 0.0};
      ASSERT_TRUE(std::isfinite(heuristic.distance(p))) << x;
      const fd::ObstacleHeuristic::Way way = heuristic.way(p);
      ASSERT_TRUE(way.known) << x;
      EXPECT_FALSE(way.room) << x;                                      // 5 m wide: less than twice turning_room
      EXPECT_LT(std::abs(normalize_angle(way.yaw)), 0.2) << "x " << x;  // along the leg, eastwards
      EXPECT_LE(way.turning, c.corners + 0.2) << "x " << x;
      EXPECT_GE(way.turning, c.corners - 0.2) << "x " << x;
      // Turned away from the way: the turn back to it comes on top (facing west, a pose travels
      // eastwards in reverse: as the aligned one).
      const double aligned = fd::turning_ahead(way, 0.0);
      EXPECT_NEAR(aligned, way.turning + std::abs(normalize_angle(way.yaw)), 1e-9);
      EXPECT_LT(aligned, fd::turning_ahead(way, 0.5));
      EXPECT_LT(aligned, fd::turning_ahead(way, -0.5));
      EXPECT_LT(fd::turning_ahead(way, 0.5), fd::turning_ahead(way, kPi / 2));
      EXPECT_LT(fd::turning_ahead(way, kPi / 2), fd::turning_ahead(way, kPi));
    }
    // On the last leg, short of the goal, nothing is left to turn.
    const Pose2 last = c.corners > 2.0 ? Pose2{12.0, 25.5, kPi} : Pose2{25.5, 15.0, kPi / 2};
    ASSERT_TRUE(std::isfinite(heuristic.distance(last)));
    const fd::ObstacleHeuristic::Way way = heuristic.way(last);
    ASSERT_TRUE(way.known);
    EXPECT_LT(std::abs(normalize_angle(way.yaw - last.yaw)), 0.2);
    EXPECT_LE(way.turning, 0.1);
  }
}

}  // namespace
}  // namespace pullout
