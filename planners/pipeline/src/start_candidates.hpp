// Internal: start-pose candidates of the search (the current pose, then poses behind it).
#pragma once

#include <string>
#include <vector>

#include "pullout/lane_planners/pull_out_planner.hpp"
#include "pullout/pipeline/parameters.hpp"

namespace pullout {

struct StartCandidate {
  Pose2 pose;
  double backward_distance{0.0};  // [m] driven in reverse to get there
};

struct StartCandidateSearch {
  std::vector<StartCandidate> candidates;
  struct Skipped {
    double backward_distance{0.0};
    std::string reason;
  };
  std::vector<Skipped> skipped;  // candidates skipped, and the one that ended the search
};

// Candidate 0 is the current pose itself, always. With enable_back, then: poses behind the
// vehicle on the line through it parallel to the pull-out lanes' centerline, every
// backward_search_resolution, as far as the room behind allows: up to max_back_distance, no
// further than keeps the rear inside the pull-out lanes, and short of the first obstacle within
// the smallest collision margin. Where the room ends between two steps, the last step is
// shortened to end there (to the pose just clear of the obstacle, within 1 mm, or exactly at the
// lanes' limit), unless it would be shorter than 5 cm. A backward candidate within
// collision_check_margin_from_front_object of a static obstacle ahead of it, or closer than
// ignore_distance_from_lane_end to the lanes' end, is skipped.
StartCandidateSearch search_start_candidates(const PlanningContext& context, const StartPlannerParameters& parameters,
                                             const Pose2& ego);

// The reverse segment from `ego` back to `candidate` along the pull-out lanes: points every
// center_line_path_interval, velocity backward_velocity, 0 at the end.
PathWithLaneId reverse_segment(const PlanningContext& context, const StartPlannerParameters& parameters,
                               const Pose2& ego, const StartCandidate& candidate);

}  // namespace pullout
