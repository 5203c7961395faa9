#pragma once
// Shared by the golden CDR tests: byte helpers, hand-written doubles, decode/serialize wrappers.

#include <cstdint>
#include <initializer_list>
#include <string>
#include <vector>

#include "serial_robot_driver/dds/c_types.h"
#include "serial_robot_driver/dds/cdr.h"
#include "serial_robot_driver/dds/messages.h"

namespace cdr_golden {

namespace dds = serial_robot_driver::dds;

using Bytes = std::vector<uint8_t>;

inline Bytes cat(std::initializer_list<Bytes> parts) {
  Bytes all;
  for (const Bytes& part : parts) all.insert(all.end(), part.begin(), part.end());
  return all;
}

inline Bytes zeros(size_t count) { return Bytes(count, 0x00); }

const Bytes kHeader{0x00, 0x01, 0x00, 0x00};
// IEEE 754 doubles, little-endian.
const Bytes kZero = zeros(8);
const Bytes kOne{0, 0, 0, 0, 0, 0, 0xf0, 0x3f};
const Bytes kMinusOne{0, 0, 0, 0, 0, 0, 0xf0, 0xbf};
const Bytes kTwo{0, 0, 0, 0, 0, 0, 0x00, 0x40};
const Bytes kThree{0, 0, 0, 0, 0, 0, 0x08, 0x40};
const Bytes kEight{0, 0, 0, 0, 0, 0, 0x20, 0x40};
const Bytes kHalf{0, 0, 0, 0, 0, 0, 0xe0, 0x3f};
const Bytes kMinusHalf{0, 0, 0, 0, 0, 0, 0xe0, 0xbf};
const Bytes kQuarter{0, 0, 0, 0, 0, 0, 0xd0, 0x3f};
const Bytes kOneAndHalf{0, 0, 0, 0, 0, 0, 0xf8, 0x3f};
const Bytes kIdentityQuaternion = cat({kZero, kZero, kZero, kOne});

// The decode direction: hand-written bytes into a zeroed sample, freed after the check.
template <typename T>
struct Decoded {
  explicit Decoded(const Bytes& bytes) {
    ok = dds::deserializeCdr(bytes, dds::Message<T>::descriptor(), &sample);
  }
  ~Decoded() { dds::freeSampleContents(dds::Message<T>::descriptor(), &sample); }
  T sample{};
  bool ok = false;
};

/// The sensor_msgs/JointState of the golden bytes (test_cdr_golden.cpp's kJointState) and its
/// storage: header {stamp {1, 2}, frame_id "base"}, name ["a", "bc"], position [1.5].
class GoldenJointState {
 public:
  GoldenJointState() : name_pointers_(names_) {
    state_.header.stamp = {1, 2};
    dds::lend(state_.header.frame_id, frame_);
    name_pointers_.lendTo(state_.name);
    dds::lend(state_.position, positions_);
  }
  GoldenJointState(const GoldenJointState&) = delete;
  GoldenJointState& operator=(const GoldenJointState&) = delete;
  const sensor_msgs_msg_dds__JointState_& sample() const { return state_; }

 private:
  const std::string frame_ = "base";
  const std::vector<std::string> names_{"a", "bc"};
  std::vector<double> positions_{1.5};
  dds::StringPointers name_pointers_;
  sensor_msgs_msg_dds__JointState_ state_{};
};

template <typename T>
Bytes serialized(const T& sample) {
  return dds::serializeCdr(dds::Message<T>::descriptor(), &sample);
}

}  // namespace cdr_golden
