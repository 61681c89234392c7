#!/usr/bin/env python3
"""Independent re-computation of Autoware's shift pull-out on its road_shoulder test map.

What Autoware's shift planner would do from the middle of a shoulder's centerline (the start of
AutowareShoulderMap), from ../shared/reference/start_planner_facts.md section 2.1 and the
planner as read, written without the project's code:
  - lanelet centerlines as Autoware's map loader makes them (bounds resampled into
    ceil(longer bound / 5 m) pieces, midpoints), the road's reference path from 5 m behind the
    start to the goal resampled every 1 m by a natural cubic spline in arc length;
  - the shift length L = the start's signed offset from the road's centerline (arc coordinates on
    the lanelet nearest to it), a_lat = 0.15, 0.2667, 0.3833, 0.5 (gentle first), jerk 0.5,
    T = 4 t_j + 2 t_a, a_lon = clamp(v_road / T, 0, 1),
    d = max(a_lon T^2 / 2, sqrt(4 L / 0.07 - L^2)), converted to centerline length
    (calcBeforeShiftedArcLength) and pushed to the first point with curvature below 0.1;
  - the end pose on the road centerline at s(start) + that distance (no candidate when that lies
    beyond the goal), the PathShifter's constant-jerk knots (velocity 1.0, a_lon, lateral
    acceleration limit a_lat) through a natural cubic spline, offset_back = false, then the
    refinement to the start pose (re-shifts until the offset changes by less than 1 cm);
  - the lane-departure check: the unexpanded footprint, oriented along the path, at every path
    point from the one nearest the start to the one nearest the end pose, inside the union of
    every lanelet of the map (the version read passes the whole map to its checker); tested on
    the footprint's outline sampled every 5 cm (a point in no lanelet is a departure);
  - the crop of points before the start whose footprint leaves the lanelets, and its validation.
No static objects: the collision check passes. For each candidate it prints the numbers and the
verdict, and for a passing one the lanelets its footprints touch beyond the route's road and the
start's shoulder chain (what the project's lane check is given).
The start, route and goal are those of AutowareShoulderMap (tests/planners/map_cases.hpp); bounds
drawn against the driving direction (49 lanelets of this map) are aligned first, as Lanelet2 does.
Usage: autoware_shift_oracle.py shoulder_id[:yaw_deg] ... [--yaw DEG ...]
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import autoware_geometric_oracle as geo  # noqa: E402  (the map, polygons and the vehicle)

LANELETS, WAYS = geo.LANELETS, geo.WAYS
FRONT, REAR, HALF = geo.FRONT, geo.REAR, geo.HALF

# Autoware's shift parameters (start_planner.param.yaml) and behavior_path_planner's lengths.
LATERAL_JERK = 0.5
MIN_LAT_ACC, MAX_LAT_ACC, LAT_ACC_SAMPLES = 0.15, 0.5, 3
MAX_CURVATURE = 0.07
END_POSE_CURVATURE_THRESHOLD = 0.1
CENTER_LINE_PATH_INTERVAL = 1.0
BACKWARD_PATH_LENGTH = 5.0
MAX_BACK_DISTANCE = 20.0
MAP_CENTERLINE_RESOLUTION = 5.0
MAXIMUM_LONGITUDINAL_DEVIATION = 1.0
OUTLINE_STEP = 0.05


# ---- the map as our test reads it (topology, lengths, speed limits) ----

BOUNDS = geo.BOUNDS  # both bounds in the driving direction (see there)


def _load_tags():
    import xml.etree.ElementTree as ET
    out = {}
    for rel in ET.parse(geo.MAP).getroot().iter("relation"):
        tags = {t.get("k"): t.get("v") for t in rel.findall("tag")}
        if tags.get("type") == "lanelet":
            out[rel.get("id")] = tags
    return out


TAGS = _load_tags()
BOUND_LENGTH = {i: 0.5 * (geo.polyline_length(b["left"]) + geo.polyline_length(b["right"])) for i, b in BOUNDS.items()}


def speed_limit_mps(lanelet_id):
    return float(TAGS[lanelet_id].get("speed_limit", "0")) / 3.6


def straight(lanelet_id):
    return TAGS[lanelet_id].get("turn_direction", "straight") == "straight"


def successors(lanelet_id):
    b = BOUNDS[lanelet_id]
    ends = (b["left_nodes"][-1], b["right_nodes"][-1])
    return sorted((j for j, k in BOUNDS.items() if (k["left_nodes"][0], k["right_nodes"][0]) == ends and j != lanelet_id),
                  key=int)


def predecessors(lanelet_id):
    b = BOUNDS[lanelet_id]
    starts = (b["left_nodes"][0], b["right_nodes"][0])
    return sorted((j for j, k in BOUNDS.items() if (k["left_nodes"][-1], k["right_nodes"][-1]) == starts and j != lanelet_id),
                  key=int)


def road_beside(shoulder):
    """The road lanelet sharing a bound with the shoulder (the last found, as shoulder_case)."""
    sh = LANELETS[shoulder]
    road = None
    for j in sorted(LANELETS, key=int):
        k = LANELETS[j]
        if k["sub"] == "road" and (k["left"] == sh["right"] or k["right"] == sh["left"]):
            road = j
    return road


def route_ahead(road, length_m=100.0):
    route, length = [road], BOUND_LENGTH[road]
    while length < length_m:
        nxt = None
        for s in successors(route[-1]):
            if LANELETS[s]["sub"] != "road" or s in route:
                continue
            if nxt is None or straight(s):
                nxt = s
        if nxt is None:
            break
        route.append(nxt)
        length += BOUND_LENGTH[nxt]
    return route


def chain_of(seed, subtype, behind, ahead):
    """seed extended through predecessors / successors of subtype (straight first, lowest id)."""
    def choose(cands, used):
        best = None
        for c in cands:
            if LANELETS[c]["sub"] != subtype or c in used:
                continue
            if best is None or (straight(c) and not straight(best)):
                best = c
        return best
    chain, covered = [seed], 0.0
    while covered < behind:
        p = choose(predecessors(chain[0]), chain)
        if p is None:
            break
        chain.insert(0, p)
        covered += BOUND_LENGTH[p]
    covered = 0.0
    while covered < ahead:
        n = choose(successors(chain[-1]), chain)
        if n is None:
            break
        chain.append(n)
        covered += BOUND_LENGTH[n]
    return chain


# ---- geometry helpers ----

def aw_centerline(lanelet_id):
    """Autoware's map-loader centerline: bounds cut into ceil(longer / 5 m) pieces, midpoints."""
    left, right = BOUNDS[lanelet_id]["left"], BOUNDS[lanelet_id]["right"]
    n = max(int(math.ceil(max(geo.polyline_length(left), geo.polyline_length(right)) / MAP_CENTERLINE_RESOLUTION)), 1)
    a, b = geo.resample(left, n), geo.resample(right, n)
    return [((p[0] + q[0]) / 2, (p[1] + q[1]) / 2) for p, q in zip(a, b)]


def our_start(shoulder):
    """The middle of the shoulder's centerline as the project derives it (0.5 m samples)."""
    left, right = BOUNDS[shoulder]["left"], BOUNDS[shoulder]["right"]
    n = max(int(math.ceil(max(geo.polyline_length(left), geo.polyline_length(right)) / 0.5)), 1)
    c = [((p[0] + q[0]) / 2, (p[1] + q[1]) / 2) for p, q in zip(geo.resample(left, n), geo.resample(right, n))]
    return geo.pose_at(c, geo.polyline_length(c) / 2)


def cumulative(line):
    s = [0.0]
    for k in range(1, len(line)):
        s.append(s[-1] + math.dist(line[k - 1], line[k]))
    return s


def natural_spline(xs, ys):
    """Coefficients of the natural cubic spline through (xs, ys), xs strictly increasing."""
    n = len(xs) - 1
    if n < 1 or any(xs[i + 1] <= xs[i] for i in range(n)):
        raise ValueError("spline keys not strictly increasing: %s" % (xs,))
    h = [xs[i + 1] - xs[i] for i in range(n)]
    m = [0.0] * (n + 1)  # second derivatives
    if n >= 2:
        a = [h[i - 1] for i in range(1, n)]
        b = [2 * (h[i - 1] + h[i]) for i in range(1, n)]
        c = [h[i] for i in range(1, n)]
        d = [6 * ((ys[i + 1] - ys[i]) / h[i] - (ys[i] - ys[i - 1]) / h[i - 1]) for i in range(1, n)]
        for i in range(1, n - 1):  # Thomas algorithm
            w = a[i] / b[i - 1]
            b[i] -= w * c[i - 1]
            d[i] -= w * d[i - 1]
        sol = [0.0] * (n - 1)
        sol[-1] = d[-1] / b[-1]
        for i in range(n - 3, -1, -1):
            sol[i] = (d[i] - c[i] * sol[i + 1]) / b[i]
        m[1:n] = sol

    def f(x):
        i = 0
        while i < n - 1 and x > xs[i + 1]:
            i += 1
        t = x - xs[i]
        hi = h[i]
        return (ys[i] + ((ys[i + 1] - ys[i]) / hi - hi * (2 * m[i] + m[i + 1]) / 6) * t + m[i] / 2 * t * t +
                (m[i + 1] - m[i]) / (6 * hi) * t ** 3)
    return f


def with_azimuth(pts):
    """(x, y, yaw) with each yaw towards the next point (the last copies the one before)."""
    out = []
    for k, p in enumerate(pts):
        q = pts[k + 1] if k + 1 < len(pts) else None
        yaw = math.atan2(q[1] - p[1], q[0] - p[0]) if q else out[-1][2]
        out.append((p[0], p[1], yaw))
    return out


def nearest_index(path, p):
    return min(range(len(path)), key=lambda i: (path[i][0] - p[0]) ** 2 + (path[i][1] - p[1]) ** 2)


def lateral_offset(path, p):
    """Signed offset (left +) of p from the path's nearest segment."""
    i = nearest_index(path, p)
    if i == len(path) - 1:
        i -= 1
    elif i > 0:
        # The segment on the side of p (findNearestSegmentIndex).
        a, b = path[i], path[i + 1]
        if (p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1]) < 0:
            i -= 1
    a, b = path[i], path[i + 1]
    seg = math.dist(a[:2], b[:2])
    return ((b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])) / seg


def menger(p1, p2, p3):
    d12, d23, d31 = math.dist(p1, p2), math.dist(p2, p3), math.dist(p3, p1)
    den = d12 * d23 * d31
    if den < 1e-12:
        return 0.0
    return 2 * ((p2[0] - p1[0]) * (p3[1] - p1[1]) - (p2[1] - p1[1]) * (p3[0] - p1[0])) / den


def curvature_and_segments(path):
    """(signed curvature, (previous segment, next segment)) per point; 0 at both ends."""
    out = [(0.0, (0.0, 0.0))]
    for i in range(1, len(path) - 1):
        out.append((menger(path[i - 1][:2], path[i][:2], path[i + 1][:2]),
                    (math.dist(path[i - 1][:2], path[i][:2]), math.dist(path[i][:2], path[i + 1][:2]))))
    out.append((0.0, (0.0, 0.0)))
    return out


# ---- lanelet polygons and the footprint test ----

POLYS = {i: b["left"] + b["right"][::-1] for i, b in BOUNDS.items()}
BOXES = {i: (min(p[0] for p in poly), min(p[1] for p in poly), max(p[0] for p in poly), max(p[1] for p in poly))
         for i, poly in POLYS.items()}


def lanelets_at(p):
    return [i for i, b in BOXES.items() if b[0] <= p[0] <= b[2] and b[1] <= p[1] <= b[3] and geo.inside(p, POLYS[i])]


def distance_to_outline(poly, p):
    """Distance from p to the closed outline of polygon `poly` (its edges, not its inside)."""
    best = math.inf
    for k in range(len(poly)):
        a, c = poly[k - 1], poly[k]
        dx, dy = c[0] - a[0], c[1] - a[1]
        L2 = dx * dx + dy * dy
        t = 0.0 if L2 == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / L2))
        best = min(best, math.dist(p, (a[0] + t * dx, a[1] + t * dy)))
    return best


def distance_to_lanelets(p):
    best = math.inf
    for i, b in BOXES.items():
        if p[0] < b[0] - best or p[0] > b[2] + best or p[1] < b[1] - best or p[1] > b[3] + best:
            continue
        poly = POLYS[i]
        best = min(best, distance_to_outline(poly, p))
    return best


def outline(pose):
    corners = geo.corners(pose)
    pts = []
    for k in range(4):
        a, b = corners[k], corners[(k + 1) % 4]
        n = max(1, int(math.ceil(math.dist(a, b) / OUTLINE_STEP)))
        pts += [(a[0] + (b[0] - a[0]) * j / n, a[1] + (b[1] - a[1]) * j / n) for j in range(n)]
    return pts


def footprint_check(pose):
    """(samples outside every lanelet, farthest of them from any lanelet [m], lanelets touched)."""
    outside, worst, touched = 0, 0.0, set()
    for p in outline(pose):
        at = lanelets_at(p)
        if at:
            touched.update(at)
        else:
            outside += 1
            worst = max(worst, distance_to_lanelets(p))
    return outside, worst, touched


# ---- Autoware's shift pull-out ----

def lat_acc_samples():
    res = max(abs(MAX_LAT_ACC - MIN_LAT_ACC) / LAT_ACC_SAMPLES, sys.float_info.epsilon)
    out, a = [], MIN_LAT_ACC
    while a <= MAX_LAT_ACC:
        out.append(a)
        a += res
    return out


def shift_time(L, j, a):
    L = abs(L)
    tj = a / j
    ta = (math.sqrt(a * a + 4 * j * j * L / a) - 3 * a) / (2 * j)
    if ta < 0:
        tj, ta = (L / (2 * j)) ** (1 / 3), 0.0
    return 4 * tj + 2 * ta


def base_lengths(S, L, v0, a_lon, lat_limit):
    """PathShifter's knots (longitudinal, lateral), offset_back = false (lateral L -> 0)."""
    a = a_lon if a_lon > 1e-4 else 0.0
    Labs = abs(L)

    def without_limit():
        return [0.0, S / 4, 3 * S / 4, S], [L, 11 * L / 12, L / 12, 0.0]
    if v0 < 1e-5 and a < 1e-4:
        return without_limit()
    T = (-v0 + math.sqrt(v0 * v0 + 2 * a * S)) / a if a > 1e-4 else S / v0
    if 8 * Labs / (T * T) < lat_limit:
        t = T / 4
        s1 = min(v0 * t + 0.5 * a * t * t, S)
        v1 = v0 + a * t
        s2 = min(s1 + 2 * v1 * t + 2 * a * t * t, S)
        return [0.0, s1, s2, S], [L, 11 * L / 12, L / 12, 0.0]
    tj = T / 2 - 2 * Labs / (lat_limit * T)
    ta = 4 * Labs / (lat_limit * T) - T / 2
    jerk = (2 * lat_limit * lat_limit * T) / (lat_limit * T * T - 4 * Labs)
    if tj < 0 or ta < 0 or jerk < 0 or tj / T < 0.1:
        return without_limit()
    s, v, lon = 0.0, v0, [0.0]
    for dt in (tj, ta, tj, tj, ta, tj):
        s = min(s + v * dt + 0.5 * a * dt * dt, S)
        v += a * dt
        lon.append(s)
    lon = lon[:3] + lon[4:]  # s3 = s4
    sg = 1.0 if L > 0 else -1.0
    tj3, ta_tj2, ta2_tj = tj ** 3, ta * tj * tj, ta * ta * tj
    lat = [0.0, jerk * tj3 / 6, jerk * (tj3 / 6 + ta_tj2 / 2 + ta2_tj / 2), jerk * (tj3 + 1.5 * ta_tj2 + 0.5 * ta2_tj),
           jerk * (11 / 6 * tj3 + 2.5 * ta_tj2 + 0.5 * ta2_tj), jerk * (11 / 6 * tj3 + 3 * ta_tj2 + ta2_tj),
           jerk * (2 * tj3 + 3 * ta_tj2 + ta2_tj)]
    return lon, [sg * x for x in reversed(lat)]


def apply_shift(path, start_xy, end_xy, L, v0, a_lon, lat_limit):
    """PathShifter::generate (spline, offset_back = false) with one shift line; None if it fails."""
    si, ei = nearest_index(path, start_xy), nearest_index(path, end_xy)
    if ei - si <= 1:
        return None
    s = cumulative([p[:2] for p in path])
    lon, lat = base_lengths(s[ei] - s[si], L, v0, a_lon, lat_limit)
    f = natural_spline(lon, lat)
    offsets = [0.0] * len(path)
    query = [f(s[i] - s[si]) for i in range(si + 1, ei)]
    for k, i in enumerate(range(si + 1, ei)):
        offsets[i] = query[k]
    for i in range(0, si + 1):
        offsets[i] = query[0]
    moved = [(x - math.sin(yaw) * o, y + math.cos(yaw) * o) for (x, y, yaw), o in zip(path, offsets)]
    dedup = [moved[0]]
    for p in moved[1:]:
        if math.dist(p, dedup[-1]) > 1e-3:
            dedup.append(p)
    return with_azimuth(dedup)


def reference_path(center, s_lanes, speed, s0, s1):
    """Road centerline points in [s0, s1] (ends exact), resampled every 1 m by a natural spline,
    the lanelet joints kept; with each point's speed limit."""
    cum = cumulative(center)
    pts, keys = [], []
    for k, p in enumerate(center):
        if s0 < cum[k] < s1:
            pts.append(p)
            keys.append(cum[k])
    for s in (s0, s1):
        x = geo.pose_at(center, s)
        if s == s0:
            pts.insert(0, x[:2])
            keys.insert(0, s)
        else:
            pts.append(x[:2])
            keys.append(s)
    keys = [k - s0 for k in keys]
    fx, fy = natural_spline(keys, [p[0] for p in pts]), natural_spline(keys, [p[1] for p in pts])
    total = keys[-1]
    # The first point of each lanelet, then every 1 m and the end, each dropped within 0.2 m of
    # one already taken (resamplePathWithSpline).
    out_s = [0.0] + [j - s0 for j in s_lanes if 0 < j - s0 < total]
    s = 0.0
    while s < total:
        if all(abs(s - q) >= 0.2 for q in out_s):
            out_s.append(s)
        s += CENTER_LINE_PATH_INTERVAL
    if all(abs(total - q) >= 0.2 for q in out_s):
        out_s.append(total)
    out_s.sort()
    path = with_azimuth([(fx(q), fy(q)) for q in out_s])
    return path, [speed(s0 + q) for q in out_s]


PATHS = []  # (a_lat, section start -> end, road centerline) of every shifted candidate


def evaluate(shoulder, yaw_deg, verbose=True):
    road = road_beside(shoulder)
    route = route_ahead(road)
    start = our_start(shoulder)
    start = (start[0], start[1], start[2] + math.radians(yaw_deg))
    # getExtendedCurrentLanes: the route's lanes from the one beside, extended 25 m back.
    back = chain_of(road, "road", BACKWARD_PATH_LENGTH + MAX_BACK_DISTANCE, 0.0)
    road_lanes = back[:-1] + route
    centers = [aw_centerline(i) for i in road_lanes]
    center, joints = [], []
    for c in centers:
        center += c if not center else c[1:]
        joints.append(geo.polyline_length(center))
    lane_end = joints

    def lane_index(s):
        for k, e in enumerate(lane_end):
            if s <= e:
                return k
        return len(lane_end) - 1

    def speed(s):
        return speed_limit_mps(road_lanes[lane_index(s)])
    # Arc coordinates on the road lanelet nearest to the start.
    near = min(range(len(road_lanes)), key=lambda k: distance_to_lanelet(road_lanes[k], start[:2]))
    s_before = lane_end[near - 1] if near > 0 else 0.0
    arc_len, L = arc_coordinates(centers[near], start[:2])
    arc_len += s_before
    s_goal = lane_end[-1]  # the goal: the end of the route's last lanelet
    s_start = max(arc_len - BACKWARD_PATH_LENGTH, 0.0)
    s_end = min(s_goal, s_start + 300.0)
    ref, speeds = reference_path(center, joints[:-1], speed, s_start, s_end)
    start_idx = nearest_index(ref, start[:2])
    v_road = speeds[start_idx]
    ref_from_ego = ref[start_idx:]
    ks = curvature_and_segments(ref_from_ego)
    our_lanes = set(road_lanes) | set(chain_of(road, "road", 25.0, 300.0)) | set(
        chain_of(shoulder, "road_shoulder", 25.0, 300.0))
    head = ("shoulder %s yaw %+g: road %s, L %.3f m, v_road %.2f m/s, goal %.1f m ahead" %
            (shoulder, yaw_deg, road_lanes, L, v_road, s_goal - arc_len))
    rows = []
    verdict = None
    if abs(L) < 0.01:
        rows.append(("start on the centerline: the reference path as it is",))
    for a_lat in lat_acc_samples():
        T = shift_time(L, LATERAL_JERK, a_lat)
        a_lon = min(max(v_road / T, 0.0), 1.0)
        d_acc = 0.5 * a_lon * T * T
        d_curv = math.sqrt(max(4 * L / MAX_CURVATURE - L * L, 0.0))
        d = max(d_acc, d_curv)
        d_conv = max(d, before_shifted(ks, d, L))
        dist = pushed_distance(ks, d_conv)
        tag = "a_lat %.4f: T %.2f s, a_lon %.3f, d %.2f m (acc %.2f, curv %.2f), on centerline %.2f, pushed %.2f" % (
            a_lat, T, a_lon, d, d_acc, d_curv, d_conv, dist)
        if dist < CENTER_LINE_PATH_INTERVAL:
            rows.append((tag, "non-shifted path (distance too short)"))
            continue
        s_shift_end = arc_len + dist
        if s_shift_end > lane_end[-1]:
            rows.append((tag, "FAIL: the shift end (s %.1f) lies beyond the road lanes (%.1f): no candidate" %
                         (s_shift_end, lane_end[-1])))
            continue
        end_pose = geo.pose_at(center, s_shift_end)
        path = apply_shift(ref, start[:2], end_pose[:2], L, 1.0, a_lon, a_lat)
        if path is None:
            rows.append((tag, "non-shifted path (shift indices adjoining)"))
            continue
        for _ in range(100):  # refineShiftedPathToStartPose
            delta = lateral_offset(path, start[:2])
            new = apply_shift(path, start[:2], end_pose[:2], delta, 0.0, a_lon, a_lat)
            if new is None:
                break
            path = new
            if abs(lateral_offset(path, start[:2]) - delta) < 0.01:
                break
        i0, i1 = nearest_index(path, start[:2]), nearest_index(path, end_pose[:2])
        PATHS.append((a_lat, path[i0:i1 + 1], center))
        miss = math.dist(path[i0][:2], start[:2])
        first_bad, touched, worst_all, bad_points = None, set(), 0.0, 0
        for i in range(i0, i1 + 1):
            out, worst, t = footprint_check(path[i])
            touched |= t
            if out:
                bad_points += 1
                worst_all = max(worst_all, worst)
                if first_bad is None:
                    first_bad = (i - i0, math.dist(path[i][:2], start[:2]), out, worst, sorted(t, key=int))
        max_k = max((abs(k) for k, _ in curvature_and_segments(path[i0:i1 + 1])), default=0.0)
        info = "%d points, first %.3f m from the start, max curvature %.3f 1/m" % (i1 - i0 + 1, miss, max_k)
        if first_bad:
            rows.append((tag, info, "FAIL lane departure: %d of %d footprints leave the lanelets, first at point %d "
                         "(%.1f m from the start, %d outline samples out, up to %.3f m; touches %s), worst %.3f m" %
                         (bad_points, i1 - i0 + 1, first_bad[0], first_bad[1], first_bad[2], first_bad[3],
                          first_bad[4], worst_all)))
            continue
        # cropPointsOutsideOfLanes before the start segment, and its validation.
        kept = [p for i, p in enumerate(path) if i > i0 or footprint_check(p)[0] == 0]
        j0 = nearest_index(kept, start[:2])
        if len(kept) < 2:
            rows.append((tag, info, "FAIL: cropped path is invalid"))
            continue
        if j0 == 0:
            off0 = longitudinal_offset(kept, 0, start[:2])
            off1 = longitudinal_offset(kept, 1, start[:2])
            if abs(off0 - off1) >= MAXIMUM_LONGITUDINAL_DEVIATION + 0.01:
                rows.append((tag, info, "FAIL: cropped path is invalid (%.2f m)" % abs(off0 - off1)))
                continue
        beyond = sorted((t for t in touched if t not in our_lanes), key=int)
        rows.append((tag, info, "PASS" + (" (footprints also in lanelets %s, outside the route's road and the "
                                          "shoulder chain)" % beyond if beyond else " (inside the route's road and "
                                          "the shoulder chain)")))
        verdict = "pass"
        break
    if verdict is None:
        verdict = "fail"
    if verbose:
        print(head)
        for r in rows:
            print("   ", " | ".join(str(x) for x in r))
    return verdict, head, rows


def distance_to_lanelet(lanelet_id, p):
    if geo.inside(p, POLYS[lanelet_id]):
        return 0.0
    return distance_to_outline(POLYS[lanelet_id], p)


def arc_coordinates(line, p):
    """(arc length of the foot point, signed distance (left +)) on the nearest segment."""
    best, s0 = None, 0.0
    for k in range(len(line) - 1):
        a, b = line[k], line[k + 1]
        seg = math.dist(a, b)
        ux, uy = (b[0] - a[0]) / seg, (b[1] - a[1]) / seg
        t = (p[0] - a[0]) * ux + (p[1] - a[1]) * uy
        tc = max(0.0, min(seg, t))
        dist = math.dist(p, (a[0] + tc * ux, a[1] + tc * uy))
        side = 1.0 if ux * (p[1] - a[1]) - uy * (p[0] - a[0]) >= 0 else -1.0
        if best is None or dist < best[0]:
            best = (dist, s0 + t, side * dist)
        s0 += seg
    return best[1], best[2]


def longitudinal_offset(path, i, p):
    a, b = path[i], path[i + 1]
    seg = math.dist(a[:2], b[:2])
    return ((p[0] - a[0]) * (b[0] - a[0]) + (p[1] - a[1]) * (b[1] - a[1])) / seg


def before_shifted(ks, target, dr):
    before, after = 0.0, 0.0
    for i, (k, (l1, l2)) in enumerate(ks):
        seg = l1 + l2 if i == len(ks) - 1 else l1
        after_seg = seg * (1 - k * dr) if k < 0 else seg / (1 + k * dr)
        if after + after_seg > target:
            off = target - after
            before += off / (1 - k * dr) if k < 0 else off * (1 + k * dr)
            break
        before += seg
        after += after_seg
    return before


def pushed_distance(ks, d_conv):
    arc, dist, min_k = 0.0, d_conv, math.inf
    for i, (k, (l1, l2)) in enumerate(ks):
        arc += l1 + l2 if i == len(ks) - 1 else l1
        if arc > d_conv:
            if abs(k) < min_k:
                min_k, dist = abs(k), arc
            if abs(k) < END_POSE_CURVATURE_THRESHOLD:
                return arc
    return dist


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("starts", nargs="+", help="shoulder id, or id:yaw_deg")
    ap.add_argument("--yaw", type=float, nargs="*", default=[0.0, 10.0, -10.0])
    args = ap.parse_args()
    print("vehicle: front %.2f m, rear %.2f m, half width %.3f m; a_lat samples %s" %
          (FRONT, REAR, HALF, ["%.4f" % a for a in lat_acc_samples()]))
    for item in args.starts:
        if ":" in item:
            sh, yaw = item.split(":")
            evaluate(sh, float(yaw))
        else:
            for yaw in args.yaw:
                evaluate(item, yaw)


if __name__ == "__main__":
    main()
