#!/usr/bin/env python3
"""Writes the project's own small Lanelet2 test maps (Autoware's OSM flavour) next to this script.

    python3 tests/maps/make_test_maps.py

straight_shoulder.osm: a 200 m straight road along +x (y in [-1.75, 1.75]) in three lanelets
101 (x 0..60), 102 (60..120), 103 (120..200); a 3 m road_shoulder on its left (y in [1.75, 4.75])
in two lanelets 201 (0..60) and 202 (60..120), sharing the road's left bound ways; an opposite
lane 301 (y in [-5.25, -1.75], driving -x) whose right bound is drawn against its direction; a
crosswalk lanelet 401 at x 150..154; road 103's right bound is drawn backwards too; a traffic light
regulatory element and a way with a dangling node reference that no lanelet uses. Speed limits
are km/h as in Autoware's maps. Nodes carry local_x/local_y and lat/lon.

two_lane_road.osm: a 200 m two-lane one-way road along +x (right-hand traffic): the right lane
111 (x 0..60), 112 (60..120), 113 (120..200) in y [-1.75, 1.75], the left lane 121, 122, 123 in
y [1.75, 5.25] beside them (sharing the bound ways: lane-change neighbours), and a 3 m
road_shoulder 211 (0..60), 212 (60..120) on the right in y [-4.75, -1.75].
"""
import math
import os

ORIGIN_LAT, ORIGIN_LON = 35.0, 139.0
M_PER_DEG_LAT = 111_000.0


class Osm:
    def __init__(self):
        self.nodes, self.ways, self.relations = [], [], []
        self.next_node, self.next_way = 1, 1001
        self.node_at = {}

    def node(self, x, y):
        key = (round(x, 3), round(y, 3))
        if key in self.node_at:
            return self.node_at[key]
        nid = self.next_node
        self.next_node += 1
        lat = ORIGIN_LAT + y / M_PER_DEG_LAT
        lon = ORIGIN_LON + x / (M_PER_DEG_LAT * math.cos(math.radians(ORIGIN_LAT)))
        self.nodes.append((nid, lat, lon, x, y))
        self.node_at[key] = nid
        return nid

    def way(self, points, tags=(), extra_refs=()):
        wid = self.next_way
        self.next_way += 1
        self.ways.append((wid, [self.node(x, y) for x, y in points] + list(extra_refs), tags))
        return wid

    def lanelet(self, rid, left, right, tags, extra=()):
        members = [("way", "left", left), ("way", "right", right)] + list(extra)
        self.relations.append((rid, members, [("type", "lanelet")] + list(tags)))

    def write(self, path):
        out = ['<?xml version="1.0" encoding="UTF-8"?>', '<osm generator="pullout make_test_maps.py">',
               '  <MetaInfo format_version="1" map_version="1"/>']
        for nid, lat, lon, x, y in self.nodes:
            out.append(f'  <node id="{nid}" lat="{lat:.10f}" lon="{lon:.10f}">')
            out.append('    <tag k="mgrs_code" v="54SUE000000"/>')
            out.append(f'    <tag k="local_x" v="{x:.4f}"/>')
            out.append(f'    <tag k="local_y" v="{y:.4f}"/>')
            out.append('    <tag k="ele" v="0.0"/>')
            out.append('  </node>')
        for wid, refs, tags in self.ways:
            out.append(f'  <way id="{wid}">')
            out += [f'    <nd ref="{r}"/>' for r in refs]
            out += [f'    <tag k="{k}" v="{v}"/>' for k, v in tags]
            out.append('  </way>')
        for rid, members, tags in self.relations:
            out.append(f'  <relation id="{rid}">')
            out += [f'    <member type="{t}" role="{role}" ref="{ref}"/>' for t, role, ref in members]
            out += [f'    <tag k="{k}" v="{v}"/>' for k, v in tags]
            out.append('  </relation>')
        out.append('</osm>')
        with open(path, "w", encoding="utf-8") as f:
            f.write("\n".join(out) + "\n")


def line(x0, x1, y, step=10.0):
    n = max(1, round(abs(x1 - x0) / step))
    return [(x0 + (x1 - x0) * i / n, y) for i in range(n + 1)]


def straight_shoulder(path):
    m = Osm()
    solid = [("type", "line_thin"), ("subtype", "solid")]
    spans = [(101, 0, 60), (102, 60, 120), (103, 120, 200)]
    left_ways = {rid: m.way(line(x0, x1, 1.75), solid) for rid, x0, x1 in spans}
    right_ways = {}
    for rid, x0, x1 in spans:
        pts = line(x0, x1, -1.75)
        right_ways[rid] = m.way(pts[::-1] if rid == 103 else pts, solid)  # 103: drawn backwards
    outer = {201: m.way(line(0, 60, 4.75), solid), 202: m.way(line(60, 120, 4.75), solid)}
    light = m.way([(155, 2.5), (155, 4.0)], [("type", "traffic_light"), ("subtype", "red_yellow_green")])
    m.relations.append((9001, [("way", "refers", light)], [("type", "regulatory_element"),
                                                           ("subtype", "traffic_light")]))
    for rid, _, _ in spans:
        tags = [("subtype", "road"), ("speed_limit", "50"), ("location", "urban"), ("one_way", "yes")]
        if rid == 103:
            tags.append(("turn_direction", "straight"))
        extra = [("relation", "regulatory_element", 9001)] if rid == 103 else []
        m.lanelet(rid, left_ways[rid], right_ways[rid], tags, extra)
    for rid, road in ((201, 101), (202, 102)):
        m.lanelet(rid, outer[rid], left_ways[road],
                  [("subtype", "road_shoulder"), ("speed_limit", "10"), ("location", "urban"), ("one_way", "yes")])
    # The opposite lane: driving -x, its left bound is the outer line at y = -5.25.
    opp_left = m.way(line(200, 0, -5.25), solid)
    opp_right = m.way(line(0, 200, -1.75), solid)  # drawn against the lane's direction
    m.lanelet(301, opp_left, opp_right, [("subtype", "road"), ("speed_limit", "50"), ("one_way", "yes")])
    cw_left = m.way([(150, -5.25), (150, 1.75)], [("type", "pedestrian_marking")])
    cw_right = m.way([(154, -5.25), (154, 1.75)], [("type", "pedestrian_marking")])
    m.lanelet(401, cw_left, cw_right, [("subtype", "crosswalk"), ("speed_limit", "10"), ("one_way", "no"),
                                       ("participant:pedestrian", "yes")])
    # A way no lanelet uses, with a node that is not in the file: must not break loading.
    m.way([(-20, 10), (-10, 10)], [("type", "virtual")], extra_refs=[999999])
    m.write(path)


def two_lane_road(path):
    m = Osm()
    dashed = [("type", "line_thin"), ("subtype", "dashed")]
    solid = [("type", "line_thin"), ("subtype", "solid")]
    spans = [(0, 0, 60), (1, 60, 120), (2, 120, 200)]
    middle = {k: m.way(line(x0, x1, 1.75), dashed) for k, x0, x1 in spans}
    right_edge = {k: m.way(line(x0, x1, -1.75), solid) for k, x0, x1 in spans}
    left_edge = {k: m.way(line(x0, x1, 5.25), solid) for k, x0, x1 in spans}
    road = [("subtype", "road"), ("speed_limit", "50"), ("location", "urban"), ("one_way", "yes")]
    for k, _, _ in spans:
        m.lanelet(111 + k, middle[k], right_edge[k], road)
        m.lanelet(121 + k, left_edge[k], middle[k], road)
    for k, x0, x1 in spans[:2]:
        outer = m.way(line(x0, x1, -4.75), solid)
        m.lanelet(211 + k, right_edge[k], outer,
                  [("subtype", "road_shoulder"), ("speed_limit", "10"), ("location", "urban"), ("one_way", "yes")])
    m.write(path)


if __name__ == "__main__":
    here = os.path.dirname(os.path.abspath(__file__))
    straight_shoulder(os.path.join(here, "straight_shoulder.osm"))
    two_lane_road(os.path.join(here, "two_lane_road.osm"))
