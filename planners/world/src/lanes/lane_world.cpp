#include "pullout/lanes/lane_world.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_set>

namespace pullout {

namespace {

constexpr double kConnectTolerance = 0.1;  // [m] bound end points closer than this connect lanes
constexpr double kEdgePieceLength = 0.5;   // [m] lane edges are split into pieces this long
constexpr double kSharedEdgeProbe = 0.05;  // [m] probe distance outside an edge piece
constexpr double kCenterlineStep = 0.5;    // [m] sampling of derived centerlines
// At most this many edge pieces or centerline steps per line: a longer line (over 50 km) gets
// longer pieces rather than unbounded memory and time.
constexpr double kMaxPieces = 1e5;

// The number of pieces of at most `step` [m] that cover `length` [m], in [1, kMaxPieces]. The
// division is clamped as a double: the length may be of any size.
std::size_t piece_count(double length, double step) {
  const double n = std::ceil(length / step);
  if (!(n >= 1.0)) return 1;  // also NaN
  return static_cast<std::size_t>(std::min(n, kMaxPieces));
}

std::vector<Vec2> to_vecs(const std::vector<Point2>& pts) {
  std::vector<Vec2> out;
  out.reserve(pts.size());
  for (const Point2& p : pts) out.push_back(to_vec(p));
  return out;
}

constexpr std::size_t kPieceVertices = 16;  // bound vertices per lane piece (each side), on average
// At most this many bound vertices strictly inside one piece, on either side: a piece that would
// hold more (the bound's vertices crowd into a short stretch of its arc length, next to a long
// edge) is cut again at its vertices, so that one point test costs at most this many edges per side.
constexpr std::size_t kMaxPieceVertices = 64;

// Appends the vertices of `line` strictly between arc lengths s0 and s1, in order, starting the
// scan at `next` (the first vertex not yet passed) and leaving it at the first vertex at or beyond
// s1: consecutive pieces share one walk along the line, so cutting costs O(vertices), not
// O(pieces x vertices).
void append_between(const Polyline& line, double s0, double s1, std::size_t& next, Polygon& out) {
  while (next < line.size() && line.s(next) <= s0 + 1e-9) ++next;
  while (next < line.size() && line.s(next) < s1 - 1e-9) out.push_back(line.point(next++));
}

// The vertices of `line` strictly between normalised arc lengths t0 and t1 (as append_between
// picks them): [first, last) indices.
std::pair<std::size_t, std::size_t> vertices_between(const Polyline& line, double t0, double t1) {
  const double s0 = t0 * line.length() + 1e-9;
  const double s1 = t1 * line.length() - 1e-9;
  std::size_t first = 0;
  std::size_t last = line.size();
  {  // first vertex with s > s0
    std::size_t lo = 0;
    std::size_t hi = line.size();
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (line.s(mid) <= s0)
        lo = mid + 1;
      else
        hi = mid;
    }
    first = lo;
  }
  {  // first vertex with s >= s1
    std::size_t lo = first;
    std::size_t hi = line.size();
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (line.s(mid) < s1)
        lo = mid + 1;
      else
        hi = mid;
    }
    last = lo;
  }
  return {first, std::max(first, last)};
}

// Appends to `cuts` the normalised arc lengths in (t0, t1) at which [t0, t1] must be cut again so
// that no part holds more than kMaxPieceVertices vertices of either bound: the middle vertex of the
// crowded side, recursively (each cut halves that side's count).
void refine_cuts(const Polyline& left, const Polyline& right, double t0, double t1, std::vector<double>& cuts,
                 int depth = 0) {
  const auto [l0, l1] = vertices_between(left, t0, t1);
  const auto [r0, r1] = vertices_between(right, t0, t1);
  const std::size_t nl = l1 - l0;
  const std::size_t nr = r1 - r0;
  if ((nl <= kMaxPieceVertices && nr <= kMaxPieceVertices) || depth > 64) return;
  const bool on_left = nl >= nr;
  const Polyline& line = on_left ? left : right;
  const std::size_t mid = on_left ? l0 + nl / 2 : r0 + nr / 2;
  const double t = line.s(mid) / line.length();
  if (!(t > t0 && t < t1)) return;  // rounding: nothing to gain
  refine_cuts(left, right, t0, t, cuts, depth + 1);
  cuts.push_back(t);
  refine_cuts(left, right, t, t1, cuts, depth + 1);
}

}  // namespace

std::vector<Polygon> cut_lane_into_pieces(const Polyline& left, const Polyline& right) {
  const std::size_t n = std::max<std::size_t>(1, std::max(left.size(), right.size()) / kPieceVertices);
  // The cuts: n pieces of equal normalised arc length, each cut again where its vertices crowd.
  std::vector<double> cuts{0.0};
  for (std::size_t k = 0; k < n; ++k) {
    const double t0 = static_cast<double>(k) / static_cast<double>(n);
    const double t1 = static_cast<double>(k + 1) / static_cast<double>(n);
    refine_cuts(left, right, t0, t1, cuts);
    cuts.push_back(t1);
  }
  std::vector<Polygon> pieces;
  pieces.reserve(cuts.size() - 1);
  std::size_t next_left = 0;
  std::size_t next_right = 0;
  for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double t0 = cuts[k];
    const double t1 = cuts[k + 1];
    Polygon piece{left.point_at(t0 * left.length())};
    append_between(left, t0 * left.length(), t1 * left.length(), next_left, piece);
    piece.push_back(left.point_at(t1 * left.length()));
    Polygon right_part{right.point_at(t0 * right.length())};
    append_between(right, t0 * right.length(), t1 * right.length(), next_right, right_part);
    right_part.push_back(right.point_at(t1 * right.length()));
    piece.insert(piece.end(), right_part.rbegin(), right_part.rend());
    pieces.push_back(std::move(piece));
  }
  return pieces;
}

namespace {

// Work items (centerline samples, edge pieces) between two checks of the stop condition.
constexpr std::size_t kStopCheckInterval = 1024;
// Point-edge tests (vertices of the lane pieces tested) between two checks, at most.
constexpr std::size_t kEdgeTestsPerCheck = std::size_t{1} << 16;
// A piece whose box covers more cells of the fine index than this goes to the coarse one.
constexpr double kMaxCellsPerPiece = 4096;

// Midline of two bounds, matched by normalised arc length. Empty when `stop` says stop first.
Polyline derive_centerline(const Polyline& left, const Polyline& right, const StopCondition& stop,
                           StopReason& stopped) {
  const double len = std::max(left.length(), right.length());
  const std::size_t n = piece_count(len, kCenterlineStep) + 1;
  std::vector<Vec2> pts;
  pts.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (i % kStopCheckInterval == 0 && (stopped = stop.check()) != StopReason::kNone) return Polyline();
    const double t = static_cast<double>(i) / static_cast<double>(n - 1);
    pts.push_back(0.5 * (left.point_at(t * left.length()) + right.point_at(t * right.length())));
  }
  return Polyline(pts);
}

}  // namespace

Polygon bounds_polygon(const Lane& lane) {
  Polygon polygon = Polyline(to_vecs(lane.left_bound)).points();
  const Polyline right(to_vecs(lane.right_bound));
  polygon.insert(polygon.end(), right.points().rbegin(), right.points().rend());
  return polygon;
}

namespace {

// The stored bits, so that -0.0 and 0.0 (equal as values) count as different input.
std::uint64_t bits_of(double v) {
  static_assert(sizeof(std::uint64_t) == sizeof(double));
  std::uint64_t bits = 0;
  std::memcpy(&bits, &v, sizeof bits);
  return bits;
}

bool identical_bits(double a, double b) { return bits_of(a) == bits_of(b); }

bool identical_points(const std::vector<Point2>& a, const std::vector<Point2>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!identical_bits(a[i].x, b[i].x) || !identical_bits(a[i].y, b[i].y)) return false;
  }
  return true;
}

}  // namespace

bool identical_lanes(const std::vector<Lane>& a, const std::vector<Lane>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Lane& x = a[i];
    const Lane& y = b[i];
    if (x.id != y.id || x.subtype != y.subtype || !identical_bits(x.speed_limit_mps, y.speed_limit_mps) ||
        !identical_points(x.left_bound, y.left_bound) || !identical_points(x.right_bound, y.right_bound) ||
        !identical_points(x.centerline, y.centerline)) {
      return false;
    }
  }
  return true;
}

bool lanes_contain(const std::vector<Lane>& lanes, const Vec2& p) {
  for (const Lane& lane : lanes) {
    const Polyline left(to_vecs(lane.left_bound));
    const Polyline right(to_vecs(lane.right_bound));
    for (const Polygon& piece : cut_lane_into_pieces(left, right)) {
      if (bounding_box(piece).contains(p) && point_in_polygon(piece, p)) return true;
    }
  }
  return false;
}

std::size_t LaneChain::lane_at(double s) const {
  const auto it = std::lower_bound(lane_end_s.begin(), lane_end_s.end(), s);
  if (it == lane_end_s.end()) return lane_end_s.empty() ? 0 : lane_end_s.size() - 1;
  return static_cast<std::size_t>(std::distance(lane_end_s.begin(), it));
}

LaneWorld::LaneWorld(const std::vector<Lane>& lanes, const StopCondition& stop) {
  lanes_.reserve(lanes.size());
  for (const Lane& in : lanes) {
    if ((stopped_ = stop.check()) != StopReason::kNone) return;
    LaneGeometry g;
    g.id = in.id;
    g.subtype = in.subtype;
    g.left = Polyline(to_vecs(in.left_bound));
    g.right = Polyline(to_vecs(in.right_bound));
    g.centerline = in.centerline.size() >= 2 ? Polyline(to_vecs(in.centerline))
                                             : derive_centerline(g.left, g.right, stop, stopped_);
    if (stopped_ != StopReason::kNone) return;
    g.polygon = g.left.points();
    g.polygon.insert(g.polygon.end(), g.right.points().rbegin(), g.right.points().rend());
    g.box = bounding_box(g.polygon);
    g.pieces = cut_lane_into_pieces(g.left, g.right);
    for (const Polygon& piece : g.pieces) g.piece_boxes.push_back(bounding_box(piece));
    g.speed_limit_mps = in.speed_limit_mps;
    work_ += g.centerline.size();
    lanes_.push_back(std::move(g));
  }
  build_topology();
  build_index(stop);
}

std::optional<std::size_t> LaneWorld::find(std::int64_t id) const {
  for (std::size_t i = 0; i < lanes_.size(); ++i) {
    if (lanes_[i].id == id) return i;
  }
  return std::nullopt;
}

void LaneWorld::build_topology() {
  for (std::size_t a = 0; a < lanes_.size(); ++a) {
    for (std::size_t b = 0; b < lanes_.size(); ++b) {
      if (a == b) continue;
      const LaneGeometry& la = lanes_[a];
      const LaneGeometry& lb = lanes_[b];
      if ((la.left.points().back() - lb.left.points().front()).norm() < kConnectTolerance &&
          (la.right.points().back() - lb.right.points().front()).norm() < kConnectTolerance) {
        lanes_[a].successors.push_back(b);
        lanes_[b].predecessors.push_back(a);
      }
    }
  }
}

void LaneWorld::build_index(const StopCondition& stop) {
  for (std::size_t i = 0; i < lanes_.size(); ++i) {
    for (std::size_t k = 0; k < lanes_[i].pieces.size(); ++k) {
      const Aabb& box = lanes_[i].piece_boxes[k];
      const std::pair<std::uint32_t, std::uint32_t> value{static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(k)};
      if (piece_index_.cell_count(box) > kMaxCellsPerPiece) {
        coarse_piece_index_.insert(box, value);
      } else {
        piece_index_.insert(box, value);
      }
    }
  }
  // An edge piece belongs to the outline of the union unless the point just outside it lies in
  // another lane (a shared bound, or the joint between consecutive lanes). Pieces are short so
  // that bounds sampled differently on the two sides are still recognised as shared.
  // The stop condition is checked every kStopCheckInterval edge pieces and every
  // kEdgeTestsPerCheck point-edge tests, whichever comes first.
  std::size_t next_check = kEdgeTestsPerCheck;
  for (std::size_t i = 0; i < lanes_.size(); ++i) {
    const Polygon& poly = lanes_[i].polygon;
    const double orientation = signed_area(poly) >= 0.0 ? 1.0 : -1.0;
    const std::size_t n = poly.size();
    for (std::size_t k = 0; k < n; ++k) {
      const Vec2 a = poly[k];
      const Vec2 b = poly[(k + 1) % n];
      const double len = (b - a).norm();
      if (len < 1e-9) continue;
      const Vec2 dir = (b - a) / len;
      // For a counter-clockwise polygon the outside is on the right of each edge.
      const Vec2 outward = -orientation * left_normal(dir);
      const std::size_t pieces = piece_count(len, kEdgePieceLength);
      // Consecutive outer pieces of one edge are merged back into one segment, so that the
      // departure test sees few long segments.
      std::optional<Vec2> run_start;
      for (std::size_t p = 0; p < pieces; ++p) {
        if ((++work_ % kStopCheckInterval == 0 || edge_tests_ >= next_check) &&
            (stopped_ = stop.check()) != StopReason::kNone) {
          return;
        }
        if (edge_tests_ >= next_check) next_check = edge_tests_ + kEdgeTestsPerCheck;
        const Vec2 pa = a + dir * (len * static_cast<double>(p) / static_cast<double>(pieces));
        const Vec2 pb = a + dir * (len * static_cast<double>(p + 1) / static_cast<double>(pieces));
        const Vec2 probe = 0.5 * (pa + pb) + kSharedEdgeProbe * outward;
        const bool shared = any_piece_containing(
            probe, i, [](std::size_t) { return true; }, &edge_tests_);
        if (!shared && !run_start) run_start = pa;
        if (shared && run_start) {
          outer_edges_.emplace_back(*run_start, pa);
          run_start.reset();
        }
      }
      if (run_start) outer_edges_.emplace_back(*run_start, b);
    }
  }
  for (std::size_t e = 0; e < outer_edges_.size(); ++e) {
    Aabb box;
    box.extend(outer_edges_[e].first);
    box.extend(outer_edges_[e].second);
    edge_index_.insert(box, static_cast<std::uint32_t>(e));
  }
}

template <typename F>
bool LaneWorld::any_piece_containing(const Vec2& p, std::size_t skip_lane, F&& accept, std::size_t* edge_tests) const {
  const auto test = [&](const std::pair<std::uint32_t, std::uint32_t>& v) {
    if (v.first == skip_lane) return false;  // before the polygon test: the lane's own pieces cost nothing
    const LaneGeometry& g = lanes_[v.first];
    if (!g.piece_boxes[v.second].contains(p)) return false;
    const Polygon& piece = g.pieces[v.second];
    if (edge_tests != nullptr) *edge_tests += piece.size();
    return point_in_polygon(piece, p) && accept(v.first);
  };
  return piece_index_.any_at(p, test) || coarse_piece_index_.any_at(p, test);
}

std::vector<std::size_t> LaneWorld::lanes_containing(const Vec2& p) const {
  std::vector<std::size_t> out;
  any_piece_containing(p, kNoLane, [&out](std::size_t lane) {
    // A point on the cut between two pieces may be reported by both.
    if (std::find(out.begin(), out.end(), lane) == out.end()) out.push_back(lane);
    return false;  // keep looking: the point may lie in several lanes
  });
  return out;
}

bool LaneWorld::contains(const Vec2& p) const {
  return any_piece_containing(p, kNoLane, [](std::size_t) { return true; });
}

std::optional<std::size_t> LaneWorld::nearest_lane(const Vec2& p, LaneSubtype subtype) const {
  std::optional<std::size_t> best;
  double best_d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < lanes_.size(); ++i) {
    if (lanes_[i].subtype != subtype || lanes_[i].centerline.size() < 2) continue;
    const double d = lanes_[i].centerline.project(p).distance;
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

const LaneChain& LaneWorld::chain_through(std::size_t seed) const {
  // Built under the lock: two threads asking for the same seed at once build it once.
  std::lock_guard<std::mutex> lock(chains_->mutex);
  const auto known = chains_->by_seed.find(seed);
  if (known != chains_->by_seed.end()) return known->second;
  std::vector<std::size_t> order{seed};
  std::unordered_set<std::size_t> seen{seed};
  for (std::size_t cur = seed; !lanes_[cur].predecessors.empty();) {
    const std::size_t prev = lanes_[cur].predecessors.front();
    if (!seen.insert(prev).second) break;
    order.insert(order.begin(), prev);
    cur = prev;
  }
  for (std::size_t cur = seed; !lanes_[cur].successors.empty();) {
    const std::size_t next = lanes_[cur].successors.front();
    if (!seen.insert(next).second) break;
    order.push_back(next);
    cur = next;
  }
  return chains_->by_seed.emplace(seed, chain_of(order)).first->second;
}

LaneChain LaneWorld::chain_of(const std::vector<std::size_t>& order) const {
  LaneChain chain;
  chain.lanes = order;
  std::vector<Vec2> pts;
  for (std::size_t idx : order) {
    const auto& c = lanes_[idx].centerline.points();
    // Consecutive centerlines share their joint point; Polyline drops the duplicate.
    pts.insert(pts.end(), c.begin(), c.end());
    chain.centerline = Polyline(pts);
    chain.lane_end_s.push_back(chain.centerline.length());
  }
  return chain;
}

bool LaneWorld::footprint_inside(const std::array<Vec2, 4>& corners) const {
  for (const Vec2& c : corners) {
    if (!contains(c)) return false;
  }
  Aabb box;
  for (const Vec2& c : corners) box.extend(c);
  const auto crosses_edge = [&](std::uint32_t e) {
    const auto& [a, b] = outer_edges_[e];
    for (std::size_t k = 0; k < 4; ++k) {
      if (segments_intersect(corners[k], corners[(k + 1) % 4], a, b)) return true;
    }
    return false;
  };
  // An edge spanning several cells is tested once per cell: cheaper than remembering it.
  return !edge_index_.any_in(box, crosses_edge);
}

}  // namespace pullout
