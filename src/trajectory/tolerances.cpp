#include "serial_robot_driver/trajectory/tolerances.h"

#include <cmath>
#include <cstdio>

namespace serial_robot_driver::trajectory {

double overrideTolerance(double default_value, double goal_value) {
  if (goal_value < 0.0) return 0.0;
  return goal_value > 0.0 ? goal_value : default_value;
}

std::vector<JointTolerance> resolveTolerances(const std::vector<std::string>& joints,
                                              const JointTolerance& defaults,
                                              const std::vector<NamedTolerance>& overrides) {
  std::vector<JointTolerance> result(joints.size(), defaults);
  for (std::size_t j = 0; j < joints.size(); ++j) {
    for (const NamedTolerance& entry : overrides) {
      if (entry.name != joints[j]) continue;
      result[j].position = overrideTolerance(defaults.position, entry.position);
      result[j].velocity = overrideTolerance(defaults.velocity, entry.velocity);
    }
  }
  return result;
}

std::optional<ToleranceViolation> findViolation(const std::vector<std::string>& joints,
                                                const std::vector<JointTolerance>& tolerances,
                                                const std::vector<JointSample>& desired,
                                                const std::vector<JointSample>& actual,
                                                const char* what) {
  for (std::size_t j = 0; j < joints.size(); ++j) {
    const struct {
      const char* quantity;
      const char* unit;
      double error;
      double tolerance;
    } checks[] = {
        {"position", "rad", actual[j].position - desired[j].position, tolerances[j].position},
        {"velocity", "rad/s", actual[j].velocity - desired[j].velocity, tolerances[j].velocity},
    };
    for (const auto& check : checks) {
      if (check.tolerance <= 0.0 || std::abs(check.error) <= check.tolerance) continue;
      char text[200];
      std::snprintf(text, sizeof(text), "joint '%s': %s error %.4f %s is beyond the %s tolerance %.4f %s",
                    joints[j].c_str(), check.quantity, check.error, check.unit, what,
                    check.tolerance, check.unit);
      return ToleranceViolation{j, text};
    }
  }
  return std::nullopt;
}

}  // namespace serial_robot_driver::trajectory
