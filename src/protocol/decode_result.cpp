#include "serial_robot_driver/protocol/decode_result.h"

namespace serial_robot_driver::protocol {

const char* toString(DecodeError error) {
  switch (error) {
    case DecodeError::kTooShort:
      return "frame too short";
    case DecodeError::kBadHeader:
      return "bad header";
    case DecodeError::kBadLength:
      return "bad length";
    case DecodeError::kBadChecksum:
      return "checksum mismatch";
    case DecodeError::kBadTail:
      return "bad tail";
    case DecodeError::kUnexpectedContent:
      return "unexpected content";
    case DecodeError::kUnknownCommand:
      return "unknown command";
  }
  return "unknown decode error";
}

}  // namespace serial_robot_driver::protocol
