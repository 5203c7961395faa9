#include "serial_robot_driver/trajectory/spline.h"

#include <algorithm>
#include <limits>

namespace serial_robot_driver::trajectory {

namespace {

/// The lesser of two orders: a segment can only use what both of its ends specify.
Interpolation lesser(Interpolation a, Interpolation b) {
  return static_cast<int>(a) < static_cast<int>(b) ? a : b;
}

JointSample atRest(const JointSample& sample) { return {sample.position, 0.0, 0.0}; }

}  // namespace

Segment::Segment(double start_time, const JointSample& start, double end_time,
                 const JointSample& end, Interpolation order)
    : start_time_(start_time), end_time_(std::max(start_time, end_time)) {
  const double T = end_time_ - start_time_;
  double* c = coefficients_;
  if (T <= 0.0) {
    c[0] = end.position;  // zero length: the end position at once
    return;
  }
  const double p0 = start.position, p1 = end.position;
  const double v0 = start.velocity, v1 = end.velocity;
  const double a0 = start.acceleration, a1 = end.acceleration;
  const double T2 = T * T, T3 = T2 * T, T4 = T3 * T, T5 = T4 * T;
  c[0] = p0;
  switch (order) {
    case Interpolation::kLinear:
      c[1] = (p1 - p0) / T;
      break;
    case Interpolation::kCubic:
      c[1] = v0;
      c[2] = (-3.0 * p0 + 3.0 * p1 - 2.0 * T * v0 - T * v1) / T2;
      c[3] = (2.0 * p0 - 2.0 * p1 + T * v0 + T * v1) / T3;
      break;
    case Interpolation::kQuintic:
      c[1] = v0;
      c[2] = 0.5 * a0;
      c[3] = (-20.0 * p0 + 20.0 * p1 - 3.0 * a0 * T2 + a1 * T2 - 12.0 * v0 * T - 8.0 * v1 * T) /
             (2.0 * T3);
      c[4] = (30.0 * p0 - 30.0 * p1 + 3.0 * a0 * T2 - 2.0 * a1 * T2 + 16.0 * v0 * T + 14.0 * v1 * T) /
             (2.0 * T4);
      c[5] = (-12.0 * p0 + 12.0 * p1 - a0 * T2 + a1 * T2 - 6.0 * v0 * T - 6.0 * v1 * T) / (2.0 * T5);
      break;
  }
}

JointSample Segment::evaluate(double t) const {
  const double* c = coefficients_;
  JointSample s;
  s.position = c[0] + t * (c[1] + t * (c[2] + t * (c[3] + t * (c[4] + t * c[5]))));
  s.velocity = c[1] + t * (2.0 * c[2] + t * (3.0 * c[3] + t * (4.0 * c[4] + t * 5.0 * c[5])));
  s.acceleration = 2.0 * c[2] + t * (6.0 * c[3] + t * (12.0 * c[4] + t * 20.0 * c[5]));
  return s;
}

JointSample Segment::sample(double time) const {
  // At its very ends the polynomial still holds (with its boundary velocity), so a spline sampled
  // where one segment hands over to the next sees no step in velocity.
  if (time < start_time_) return atRest(evaluate(0.0));
  if (time > end_time_) return atRest(evaluate(end_time_ - start_time_));
  return evaluate(time - start_time_);
}

void Segment::truncate(double time) { end_time_ = std::clamp(time, start_time_, end_time_); }

JointSample JointSpline::sample(double time) const {
  if (segments_.empty()) return hold_;
  if (time <= segments_.front().startTime()) return segments_.front().sample(time);
  // The last segment that has started; segments are in time order and do not overlap.
  auto it = std::upper_bound(segments_.begin(), segments_.end(), time,
                             [](double t, const Segment& s) { return t < s.startTime(); });
  return std::prev(it)->sample(time);
}

std::optional<SegmentSpan> JointSpline::segmentAt(double time) const {
  for (const Segment& segment : segments_) {
    if (segment.startTime() <= time && time < segment.endTime()) {
      return SegmentSpan{segment.startTime(), segment.endTime(), segment.sample(segment.endTime())};
    }
  }
  return std::nullopt;
}

double JointSpline::endTime() const {
  return segments_.empty() ? -std::numeric_limits<double>::infinity() : segments_.back().endTime();
}

void JointSpline::splice(double from, const std::vector<Waypoint>& waypoints) {
  const JointSample start = sample(from);
  // Keep what ran before `from`; a segment running at `from` ends there.
  while (!segments_.empty() && segments_.back().startTime() >= from) segments_.pop_back();
  if (!segments_.empty()) segments_.back().truncate(from);
  if (waypoints.empty()) {
    segments_.clear();
    hold_ = atRest(start);
    return;
  }
  // The bridge starts from the full state (position, velocity, acceleration), so its order is
  // the first waypoint's.
  segments_.emplace_back(from, start, waypoints.front().time, waypoints.front().sample,
                         waypoints.front().order);
  for (std::size_t i = 1; i < waypoints.size(); ++i) {
    const Waypoint& a = waypoints[i - 1];
    const Waypoint& b = waypoints[i];
    segments_.emplace_back(a.time, a.sample, b.time, b.sample, lesser(a.order, b.order));
  }
  hold_ = atRest(waypoints.back().sample);
}

void JointSpline::prune(double time) {
  auto first_kept = std::find_if(segments_.begin(), segments_.end(),
                                 [&](const Segment& s) { return s.endTime() >= time; });
  if (first_kept == segments_.end() && !segments_.empty()) hold_ = atRest(segments_.back().sample(time));
  segments_.erase(segments_.begin(), first_kept);
}

}  // namespace serial_robot_driver::trajectory
