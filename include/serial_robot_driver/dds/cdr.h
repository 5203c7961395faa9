#pragma once
// CDR (XCDR1, what ROS 2 uses on DDS) of the generated types, through Cyclone's own serializer:
// the 4-byte encapsulation header (00 01 00 00: CDR little-endian, no options) and the payload,
// aligned relative to the end of the header. Used by tests and tools that need the bytes; the
// Publisher/Subscription leave serialization to Cyclone. On the wire Cyclone also pads the payload
// to a multiple of 4 and counts the padding in the options' low bits (XTypes 1.3): a 1-byte Bool
// goes out as 00 01 00 03 01 00 00 00; deserializeCdr() takes both forms.

#include <dds/dds.h>

#include <cstdint>
#include <vector>

namespace serial_robot_driver {
namespace dds {

/// The serialized form of `sample` (a struct of `type`), header included.
std::vector<uint8_t> serializeCdr(const dds_topic_descriptor_t& type, const void* sample);

/// Decodes `bytes` (header included, little- or big-endian CDR) into `sample`, which must be
/// zero-initialised or hold contents of a previous decode. False, with `sample` untouched, for
/// bytes that are not a valid `type` (short, bad lengths, unknown encapsulation): never reads past
/// them.
/// Release what was decoded with freeSampleContents().
bool deserializeCdr(const std::vector<uint8_t>& bytes, const dds_topic_descriptor_t& type,
                    void* sample);

/// Frees the strings and sequences a decode allocated in `sample` (not `sample` itself).
void freeSampleContents(const dds_topic_descriptor_t& type, void* sample);

}  // namespace dds
}  // namespace serial_robot_driver
