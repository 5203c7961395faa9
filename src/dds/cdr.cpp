// CDR through Cyclone's stream functions (the same code that serializes samples for the wire).
#include "serial_robot_driver/dds/cdr.h"

#include <dds/ddsi/ddsi_cdrstream.h>

#include <cstring>

namespace serial_robot_driver {
namespace dds {

namespace {

constexpr uint32_t kXcdr1 = 1;  // Cyclone's CDR_ENC_VERSION_1
constexpr size_t kHeaderSize = 4;
// Encapsulation identifiers (first two header bytes, big-endian on the wire): CDR_BE, CDR_LE.
constexpr uint8_t kCdrBigEndian = 0x00;
constexpr uint8_t kCdrLittleEndian = 0x01;

bool hostIsLittleEndian() {
  const uint16_t one = 1;
  uint8_t first = 0;
  std::memcpy(&first, &one, 1);
  return first == 1;
}

}  // namespace

std::vector<uint8_t> serializeCdr(const dds_topic_descriptor_t& type, const void* sample) {
  dds_ostream_t stream;
  dds_ostream_init(&stream, 0, kXcdr1);
  dds_stream_write(&stream, static_cast<const char*>(sample), type.m_ops);
  std::vector<uint8_t> bytes(kHeaderSize + stream.m_index, 0x00);
  bytes[1] = hostIsLittleEndian() ? kCdrLittleEndian : kCdrBigEndian;
  if (stream.m_index > 0) std::memcpy(&bytes[kHeaderSize], stream.m_buffer, stream.m_index);
  dds_ostream_fini(&stream);
  return bytes;
}

bool deserializeCdr(const std::vector<uint8_t>& bytes, const dds_topic_descriptor_t& type,
                    void* sample) {
  if (bytes.size() <= kHeaderSize || bytes[0] != 0x00 ||
      (bytes[1] != kCdrBigEndian && bytes[1] != kCdrLittleEndian)) {
    return false;
  }
  const bool little_endian = bytes[1] == kCdrLittleEndian;
  // XTypes: the options' two low bits count the padding that ends the payload (Cyclone pads to 4).
  const size_t padding = bytes[3] & 0x03;
  if (bytes.size() - kHeaderSize <= padding) return false;
  // Normalizing validates every length against the buffer (and swaps to host order) in place.
  std::vector<char> payload(bytes.begin() + kHeaderSize, bytes.end() - padding);
  uint32_t offset = 0;
  const auto size = static_cast<uint32_t>(payload.size());
  if (!dds_stream_normalize_data(payload.data(), &offset, size,
                                 little_endian != hostIsLittleEndian(), kXcdr1, type.m_ops)) {
    return false;
  }
  dds_istream_t stream;
  dds_istream_init(&stream, size, payload.data(), kXcdr1);
  dds_stream_read(&stream, static_cast<char*>(sample), type.m_ops);
  dds_istream_fini(&stream);
  return true;
}

void freeSampleContents(const dds_topic_descriptor_t& type, void* sample) {
  dds_sample_free(sample, &type, DDS_FREE_CONTENTS);
}

}  // namespace dds
}  // namespace serial_robot_driver
