// The one conversion between the plain model (pullout/model/types.hpp) and the DDS types generated
// from idl/pullout.idl. Both DDS edges (service/ and client/) use it; nothing else sees generated
// types.
//
// Poses: the model keeps (x, y, yaw); messages carry a position and a unit quaternion. to_msg
// writes z = 0 and a yaw-only quaternion. from_msg for requests and progress validates: a
// non-finite value or a quaternion whose norm differs from 1 by more than 1e-3 is reported as a
// RequestIssue naming the field (e.g. "ego_pose.orientation"), and the yaw of the normalised
// quaternion is used for everything else.
#pragma once

#include <vector>

#include "pullout/model/types.hpp"
#include "pullout/msg/pullout.h"

namespace pullout::idl {

msg::PullOutRequest to_msg(const PullOutRequest& in);
// Converts and validates the message-level encoding; issues are appended to `issues`.
PullOutRequest from_msg(const msg::PullOutRequest& in, std::vector<RequestIssue>& issues);

msg::PullOutPath to_msg(const PullOutPath& in);
PullOutPath from_msg(const msg::PullOutPath& in);

msg::PullOutStatus to_msg(const PullOutStatus& in);
// Checks the enumerations a receiver acts on: an evaluation-table outcome outside the IDL's
// AttemptOutcome is reported as "evaluation_table[i].outcome" (the row keeps kNoPath and the raw
// value in its detail). Other enumerators map leniently to their neutral value.
PullOutStatus from_msg(const msg::PullOutStatus& in, std::vector<RequestIssue>& issues);
// The same, the issues dropped.
PullOutStatus from_msg(const msg::PullOutStatus& in);

msg::ExecutionProgress to_msg(const ExecutionProgress& in);
ExecutionProgress from_msg(const msg::ExecutionProgress& in, std::vector<RequestIssue>& issues);

// Nanoseconds since the epoch <-> msg::Time.
msg::Time to_msg_time(std::int64_t stamp_ns);
std::int64_t from_msg_time(const msg::Time& t);

}  // namespace pullout::idl
