// Vehicle dimensions and steering limit, in the base_link frame (the rear-axle centre, +x forward).
#pragma once

#include <cmath>

namespace pullout {

struct VehicleInfo {
  double wheel_base_m{2.79};
  double wheel_tread_m{1.64};
  double front_overhang_m{1.0};
  double rear_overhang_m{1.1};
  double left_overhang_m{0.128};
  double right_overhang_m{0.128};
  double max_steer_angle_rad{0.70};

  double base_to_front_m() const { return wheel_base_m + front_overhang_m; }
  double base_to_rear_m() const { return rear_overhang_m; }
  double length_m() const { return base_to_front_m() + base_to_rear_m(); }
  double base_to_left_m() const { return wheel_tread_m / 2.0 + left_overhang_m; }
  double base_to_right_m() const { return wheel_tread_m / 2.0 + right_overhang_m; }
  double width_m() const { return base_to_left_m() + base_to_right_m(); }
  // Minimum turning radius of the rear-axle centre at max steer [m].
  double min_turning_radius_m() const { return wheel_base_m / std::tan(max_steer_angle_rad); }
};

}  // namespace pullout
