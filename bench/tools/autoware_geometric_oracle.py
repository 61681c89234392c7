#!/usr/bin/env python3
"""Independent re-computation of Autoware's geometric pull-out on its road_shoulder test map.

What Autoware's planner would do from the middle of a shoulder's centerline, from the formulas in
../shared/reference/start_planner_facts.md section 2.2, written without the project's code:
  - the end pose candidates: 2 sqrt(R^2 - (R - d/2)^2) ahead of the start on the road centerline
    (d the start's offset from it, R = R_min), then 0..9 m further; none beyond the route's road;
  - the near arc's radius R2 = (dC^2 - R^2) / (2 (R + dC cos(alpha))), the first arc (out of the
    shoulder) at R_min turning towards the road;
  - the analytic far-bound check: |distance of the end pose to the road lane's far bound| -
    (hypot(R2 + w/2, base_link2front) - R2) >= lane_departure_margin (0.2 m);
  - the footprint check: every corner of the (unexpanded) footprint at every pose of both arcs,
    sampled every 1 m (arc_path_interval) as Autoware's, inside some lanelet of the whole map (the
    lanes Autoware's checker is given in the version read).
The road is the road lanelet sharing the shoulder's bound and its road successors (first found),
as the test's route. Bounds drawn against the driving direction (49 lanelets of this map) are
aligned first, as Lanelet2 and the project's loader do (BOUNDS; shared with the shift script).
Usage: autoware_geometric_oracle.py [shoulder_id ...] [--yaw DEG]
"""
import argparse
import math
import os
import xml.etree.ElementTree as ET

HERE = os.path.dirname(os.path.abspath(__file__))
MAP = os.path.join(HERE, "..", "..", "..", "shared", "maps", "autoware_road_shoulder", "lanelet2_map.osm")

# The project's default vehicle (config/pullout.yaml) and Autoware's geometric parameters.
WHEEL_BASE, FRONT_OVERHANG, REAR_OVERHANG = 2.79, 1.0, 1.1
WIDTH = 1.64 + 2 * 0.128
FRONT, REAR, HALF = WHEEL_BASE + FRONT_OVERHANG, REAR_OVERHANG, WIDTH / 2
R_MIN = WHEEL_BASE / math.tan(0.7 * 0.72)
MARGIN = 0.2
ARC_INTERVAL = 1.0


def load(path):
    root = ET.parse(path).getroot()
    nodes, ways, lanelets = {}, {}, {}
    for n in root.iter("node"):
        tags = {t.get("k"): t.get("v") for t in n.findall("tag")}
        if "local_x" in tags:
            nodes[n.get("id")] = (float(tags["local_x"]), float(tags["local_y"]))
    for w in root.iter("way"):
        ways[w.get("id")] = [nd.get("ref") for nd in w.findall("nd")]
    for rel in root.iter("relation"):
        tags = {t.get("k"): t.get("v") for t in rel.findall("tag")}
        if tags.get("type") != "lanelet":
            continue
        members = {m.get("role"): m.get("ref") for m in rel.findall("member") if m.get("type") == "way"}
        lanelets[rel.get("id")] = {"left": members["left"], "right": members["right"], "sub": tags.get("subtype")}
    return nodes, ways, lanelets


NODES, WAYS, LANELETS = load(MAP)


def points(way):
    return [NODES[i] for i in WAYS[way]]


def polyline_length(line):
    return sum(math.dist(line[k], line[k + 1]) for k in range(len(line) - 1))


def resample(line, n):
    cum = [0.0]
    for k in range(1, len(line)):
        cum.append(cum[-1] + math.dist(line[k - 1], line[k]))
    out = []
    j = 0
    for k in range(n + 1):
        s = cum[-1] * k / n
        while j < len(line) - 2 and cum[j + 1] < s:
            j += 1
        t = (s - cum[j]) / max(cum[j + 1] - cum[j], 1e-12)
        out.append((line[j][0] + t * (line[j + 1][0] - line[j][0]), line[j][1] + t * (line[j + 1][1] - line[j][1])))
    return out


def _side_of(line, p):
    """> 0 when p lies left of the polyline (judged at its nearest segment), < 0 right."""
    best = (math.inf, 0.0)
    for k in range(1, len(line)):
        a, b = line[k - 1], line[k]
        dx, dy = b[0] - a[0], b[1] - a[1]
        L2 = dx * dx + dy * dy
        if L2 <= 0:
            continue
        t = max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / L2))
        d = math.dist(p, (a[0] + t * dx, a[1] + t * dy))
        if d < best[0]:
            best = (d, dx * (p[1] - a[1]) - dy * (p[0] - a[0]))
    return best[1]


def _aligned(lanelet_id):
    """Both bounds' (points, node ids) in the driving direction: a bound drawn the other way (the
    map has some) is reversed, each judged against the other as drawn (as the project's loader
    and Lanelet2 do)."""
    ll = LANELETS[lanelet_id]
    left, right = list(WAYS[ll["left"]]), list(WAYS[ll["right"]])
    lp, rp = [NODES[i] for i in left], [NODES[i] for i in right]
    rev_right = _side_of(rp, resample(lp, 2)[1]) < 0
    rev_left = _side_of(lp, resample(rp, 2)[1]) > 0
    if rev_right:
        right.reverse()
        rp.reverse()
    if rev_left:
        left.reverse()
        lp.reverse()
    return {"left": lp, "right": rp, "left_nodes": left, "right_nodes": right}


BOUNDS = {i: _aligned(i) for i in LANELETS}


def centerline(lanelet_id, n=100):
    a = resample(BOUNDS[lanelet_id]["left"], n)
    b = resample(BOUNDS[lanelet_id]["right"], n)
    return [((p[0] + q[0]) / 2, (p[1] + q[1]) / 2) for p, q in zip(a, b)]


def polygon(lanelet_id):
    return BOUNDS[lanelet_id]["left"] + BOUNDS[lanelet_id]["right"][::-1]


def inside(p, poly):
    c = False
    for k in range(len(poly)):
        a, b = poly[k], poly[k - 1]
        if (a[1] > p[1]) != (b[1] > p[1]) and p[0] < (b[0] - a[0]) * (p[1] - a[1]) / (b[1] - a[1]) + a[0]:
            c = not c
    return c


ALL_POLYGONS = [polygon(i) for i in LANELETS]


def project(line, p):
    """(arc length, signed lateral offset (left +), heading) of p's closest point on line."""
    best = None
    s0 = 0.0
    for k in range(len(line) - 1):
        a, b = line[k], line[k + 1]
        seg = math.dist(a, b)
        ux, uy = (b[0] - a[0]) / seg, (b[1] - a[1]) / seg
        t = max(0.0, min(seg, (p[0] - a[0]) * ux + (p[1] - a[1]) * uy))
        dist = math.dist(p, (a[0] + t * ux, a[1] + t * uy))
        if best is None or dist < best[0]:
            best = (dist, s0 + t, -(p[0] - a[0]) * uy + (p[1] - a[1]) * ux, math.atan2(uy, ux))
        s0 += seg
    return best[1], best[2], best[3]


def pose_at(line, s):
    s0 = 0.0
    for k in range(len(line) - 1):
        a, b = line[k], line[k + 1]
        seg = math.dist(a, b)
        if s <= s0 + seg or k == len(line) - 2:
            t = (s - s0) / seg
            return (a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), math.atan2(b[1] - a[1], b[0] - a[0]))
        s0 += seg


def corners(pose):
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    return [(x + c * lx - s * ly, y + s * lx + c * ly) for lx, ly in ((FRONT, HALF), (FRONT, -HALF), (-REAR, -HALF), (-REAR, HALF))]


def successors(lanelet_id):
    ends = (BOUNDS[lanelet_id]["left_nodes"][-1], BOUNDS[lanelet_id]["right_nodes"][-1])
    return [j for j, k in BOUNDS.items() if (k["left_nodes"][0], k["right_nodes"][0]) == ends and j != lanelet_id]


def road_beside(shoulder):
    """(road ids ahead, centerline, far bound, shoulder on the left) for the road sharing a bound."""
    sh = LANELETS[shoulder]
    for j, k in LANELETS.items():
        if k["sub"] != "road":
            continue
        if k["left"] == sh["right"] or k["right"] == sh["left"]:
            left = k["left"] == sh["right"]
            ids = [j]
            while len(ids) < 5:
                nxt = [i for i in successors(ids[-1]) if LANELETS[i]["sub"] == "road"]
                if not nxt:
                    break
                ids.append(nxt[0])
            center, far = [], []
            for i in ids:
                c = centerline(i)
                center += c if not center else c[1:]
                b = BOUNDS[i]["right" if left else "left"]
                far += b if not far else b[1:]
            return ids, center, far, left
    return None


def arc_poses(center, radius, a0, a1, clockwise):
    da = (a1 - a0 + math.pi) % (2 * math.pi) - math.pi
    n = max(1, int(abs(da) * radius / ARC_INTERVAL) + 1)
    out = []
    for k in range(n + 1):
        a = a0 + da * k / n
        yaw = a - math.pi / 2 if clockwise else a + math.pi / 2
        out.append((center[0] + radius * math.cos(a), center[1] + radius * math.sin(a), yaw))
    return out, math.degrees(da)


def evaluate(shoulder, yaw_offset_deg):
    ids, center, far_bound, left = road_beside(shoulder)
    sc = centerline(shoulder)
    ego = pose_at(sc, polyline_length(sc) / 2)
    ego = (ego[0], ego[1], ego[2] + math.radians(yaw_offset_deg))
    road_length = polyline_length(center)
    _, d, _ = project(center, ego[:2])
    sgn = 1.0 if left else -1.0  # +1: the shoulder (start) is left of the road
    rows = []
    q = R_MIN ** 2 - (-sgn * d / 2 + R_MIN) ** 2
    if q < 0:
        return ids, d, [("no end pose (start too far from the road)",)]
    dx = 2 * math.sqrt(q)
    c, s = math.cos(ego[2]), math.sin(ego[2])
    s_base, _, _ = project(center, (ego[0] + c * dx + s * d, ego[1] + s * dx - c * d))
    for off in range(10):
        if s_base + off > road_length:
            rows.append((off, "end pose beyond the route's road (s %.2f > %.2f)" % (s_base + off, road_length)))
            continue
        e = pose_at(center, s_base + off)
        psi = e[2] - ego[2]
        # First arc's centre: R_min beside the start, on the road side.
        cf = (ego[0] + sgn * s * R_MIN, ego[1] - sgn * c * R_MIN)
        dc = math.dist(cf, e[:2])
        y_end = -(e[0] - ego[0]) * s + (e[1] - ego[1]) * c  # end in the start's frame (left +)
        alpha = math.pi / 2 - sgn * psi + math.asin((sgn * y_end + R_MIN) / dc)
        r2 = (dc * dc - R_MIN ** 2) / (2 * (R_MIN + dc * math.cos(alpha)))
        if r2 <= 0:
            rows.append((off, "R2 <= 0"))
            continue
        swing = math.hypot(r2 + HALF, FRONT) - r2
        _, far, _ = project(far_bound, e[:2])
        room = abs(far) - swing
        cn = (e[0] - sgn * math.sin(e[2]) * r2, e[1] + sgn * math.cos(e[2]) * r2)
        t = (cf[0] + (cn[0] - cf[0]) * R_MIN / (R_MIN + r2), cf[1] + (cn[1] - cf[1]) * R_MIN / (R_MIN + r2))
        arc1, turn1 = arc_poses(cf, R_MIN, math.atan2(ego[1] - cf[1], ego[0] - cf[0]), math.atan2(t[1] - cf[1], t[0] - cf[0]), left)
        arc2, turn2 = arc_poses(cn, r2, math.atan2(t[1] - cn[1], t[0] - cn[0]), math.atan2(e[1] - cn[1], e[0] - cn[0]), not left)
        poses = arc1 + arc2
        outside = sum(1 for p in poses for q2 in corners(p) if not any(inside(q2, poly) for poly in ALL_POLYGONS))
        rows.append((off, "arcs %+.1f / %+.1f deg" % (turn1, turn2), "R2 %.2f m" % r2, "far bound %.2f m" % abs(far),
                     "swing %.2f m" % swing, "room %+.2f m: %s" % (room - MARGIN, "pass" if room >= MARGIN else "FAIL"),
                     "corners outside the map %d of %d" % (outside, 4 * len(poses))))
    return ids, d, rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("shoulders", nargs="*", default=["15222", "15232"])
    ap.add_argument("--yaw", type=float, nargs="*", default=[0.0, 10.0, -10.0])
    args = ap.parse_args()
    print("R_min %.3f m, footprint front %.2f rear %.2f half width %.3f m" % (R_MIN, FRONT, REAR, HALF))
    for sh in args.shoulders:
        for yaw in args.yaw:
            ids, d, rows = evaluate(sh, yaw)
            print("shoulder %s yaw %+g: road %s, start %.2f m from its centerline" % (sh, yaw, ids, d))
            for r in rows:
                print("   ", " | ".join(str(x) for x in r))


if __name__ == "__main__":
    main()
