// Reading the CLI's SVG pictures back in tests: parse (tinyxml2, strict XML), find elements by
// class, read their points; a small road scene.
#pragma once

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <tinyxml2.h>

#include "pullout/model/types.hpp"

namespace pullout::cli::svg_testing {

// A 60 m road with a shoulder, a car on the shoulder ahead of the vehicle, a triangle on the road.
inline PullOutRequest scene() {
  PullOutRequest request;
  Lane road;
  road.id = 1;
  road.subtype = LaneSubtype::kRoad;
  road.left_bound = {{0.0, 1.75}, {60.0, 1.75}};
  road.right_bound = {{0.0, -1.75}, {60.0, -1.75}};
  road.centerline = {{0.0, 0.0}, {60.0, 0.0}};
  Lane shoulder;
  shoulder.id = 2;
  shoulder.subtype = LaneSubtype::kRoadShoulder;
  shoulder.left_bound = {{0.0, 4.75}, {60.0, 4.75}};
  shoulder.right_bound = {{0.0, 1.75}, {60.0, 1.75}};
  request.lanes = {road, shoulder};
  Object car;
  car.id = 7;
  car.object_class = ObjectClass::kCar;
  car.pose = {20.0, 3.25, 0.0};
  Object triangle;
  triangle.id = 8;
  triangle.pose = {40.0, -1.0, 0.0};
  triangle.polygon = {{1.0, 0.0}, {-1.0, 1.0}, {-1.0, -1.0}};
  request.objects = {car, triangle};
  request.ego_pose = {10.0, 3.25, 0.0};
  request.goal_pose = {55.0, 0.0, 0.0};
  return request;
}

struct Parsed {
  tinyxml2::XMLDocument doc;
  const tinyxml2::XMLElement* root{nullptr};
  std::vector<const tinyxml2::XMLElement*> elements;  // every element, depth first
};

inline void collect(const tinyxml2::XMLElement* e, std::vector<const tinyxml2::XMLElement*>& out) {
  for (; e != nullptr; e = e->NextSiblingElement()) {
    out.push_back(e);
    collect(e->FirstChildElement(), out);
  }
}

inline void parse(const std::string& svg, Parsed& parsed) {
  ASSERT_EQ(parsed.doc.Parse(svg.c_str()), tinyxml2::XML_SUCCESS) << parsed.doc.ErrorStr() << "\n" << svg;
  parsed.root = parsed.doc.RootElement();
  ASSERT_NE(parsed.root, nullptr);
  collect(parsed.root, parsed.elements);
}

inline std::vector<const tinyxml2::XMLElement*> with_class(const Parsed& p, const std::string& css_class) {
  std::vector<const tinyxml2::XMLElement*> out;
  for (const auto* e : p.elements) {
    const char* c = e->Attribute("class");
    if (c != nullptr && css_class == c) out.push_back(e);
  }
  return out;
}

inline std::vector<Point2> points_of(const tinyxml2::XMLElement* e) {
  std::vector<Point2> out;
  std::istringstream in(e->Attribute("points"));
  std::string pair;
  while (in >> pair) {
    Point2 p;
    EXPECT_EQ(std::sscanf(pair.c_str(), "%lf,%lf", &p.x, &p.y), 2) << pair;
    out.push_back(p);
  }
  return out;
}

inline std::string all_text(const Parsed& p) {
  std::string out;
  for (const auto* e : p.elements) {
    if (e->GetText() != nullptr) out += std::string(e->GetText()) + "\n";
  }
  return out;
}

}  // namespace pullout::cli::svg_testing
