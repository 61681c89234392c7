// The human-readable output of the pullout CLI (the default; --json replaces it).
#pragma once

#include <ostream>

#include "report.hpp"

namespace pullout::cli {

// Writes: found / planner / state; one line per segment (direction, points, length, terminal
// velocity and acceleration); start and end pose; the evaluation table; the planning time; the
// reasons when nothing was found; the error lines of a rejected request.
void print_report(std::ostream& out, const PlanReport& report);

}  // namespace pullout::cli
