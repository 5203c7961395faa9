// Typed decode errors shared by every codec. Decoders never throw: they return a Decoded<T> that
// holds either the value or the reason, and the device layer turns the reason into a counter/log.
#pragma once

#include <cassert>
#include <cstddef>
#include <variant>

namespace serial_robot_driver::protocol {

enum class DecodeError {
  kTooShort,       ///< fewer bytes than the smallest frame of that kind
  kBadHeader,      ///< the frame does not start with the family's header
  kBadLength,      ///< the LEN field contradicts the frame size or the configuration
  kBadChecksum,    ///< XOR / sum / CRC mismatch
  kBadTail,        ///< telemetry tail is not 1F 2F
  kUnexpectedContent,  ///< well-framed, but the payload does not fit the command
  kUnknownCommand,     ///< a command byte the protocol does not define (servo bus CMD)
};

const char* toString(DecodeError error);

/// What a codec's probe says about the bytes at a stream position: the framer asks it and knows
/// nothing of the layout itself.
struct Probe {
  enum class Status { kNeedMore, kInvalid, kFrame };
  Status status = Status::kNeedMore;
  DecodeError reason = DecodeError::kTooShort;  ///< why, for kInvalid
  std::size_t size = 0;                         ///< frame size, for kFrame

  static constexpr Probe needMore() { return {Status::kNeedMore, DecodeError::kTooShort, 0}; }
  static constexpr Probe invalid(DecodeError why) { return {Status::kInvalid, why, 0}; }
  static constexpr Probe frame(std::size_t bytes) {
    return {Status::kFrame, DecodeError::kTooShort, bytes};
  }
};

template <typename T>
class Decoded {
 public:
  Decoded(T value) : state_(std::move(value)) {}  // NOLINT(google-explicit-constructor)
  Decoded(DecodeError error) : state_(error) {}   // NOLINT(google-explicit-constructor)

  bool ok() const { return std::holds_alternative<T>(state_); }
  explicit operator bool() const { return ok(); }
  const T& value() const {
    assert(ok());
    return std::get<T>(state_);
  }
  const T& operator*() const { return value(); }
  const T* operator->() const { return &value(); }
  DecodeError error() const {
    assert(!ok());
    return std::get<DecodeError>(state_);
  }

 private:
  std::variant<T, DecodeError> state_;
};

}  // namespace serial_robot_driver::protocol
