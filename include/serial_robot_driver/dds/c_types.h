#pragma once
// Filling and reading the idlc-generated C structs from C++ without copies on the write path.
//
// Writing: a sample only has to live until Publisher::publish() returns (Cyclone serializes it
// there), so its strings and sequences can point into C++ storage: lend() sets the pointers, the
// storage stays owned by the caller and must outlive the publish() call.
// Reading: a received sample is valid during the callback only; copy out what you keep.

#include <string>
#include <type_traits>
#include <vector>

namespace serial_robot_driver {
namespace dds {

/// `field` (a `char*` string member) points at `text`.
inline void lend(char*& field, const std::string& text) { field = const_cast<char*>(text.c_str()); }

/// `sequence` (any generated dds_sequence_*) points at `elements`; it never frees them
/// (_release false).
template <typename Sequence, typename Element>
void lend(Sequence& sequence, std::vector<Element>& elements) {
  static_assert(std::is_same<decltype(sequence._buffer), Element*>::value,
                "the sequence's element type and the vector's differ");
  sequence._buffer = elements.data();
  sequence._length = static_cast<uint32_t>(elements.size());
  sequence._maximum = sequence._length;
  sequence._release = false;
}

/// The `char*` array a string sequence points at, for strings that outlive it.
class StringPointers {
 public:
  explicit StringPointers(const std::vector<std::string>& strings) {
    for (const std::string& text : strings) pointers_.push_back(const_cast<char*>(text.c_str()));
  }
  template <typename StringSequence>
  void lendTo(StringSequence& sequence) {
    lend(sequence, pointers_);
  }

 private:
  std::vector<char*> pointers_;
};

/// A received string ("" for a null pointer).
inline std::string text(const char* field) { return field ? std::string(field) : std::string(); }

/// A received sequence of numbers or structs, copied.
template <typename Sequence>
auto toVector(const Sequence& sequence)
    -> std::vector<std::remove_pointer_t<decltype(sequence._buffer)>> {
  if (sequence._length == 0 || sequence._buffer == nullptr) return {};
  return {sequence._buffer, sequence._buffer + sequence._length};
}

/// A received sequence of strings, copied.
template <typename StringSequence>
std::vector<std::string> toStrings(const StringSequence& sequence) {
  std::vector<std::string> strings;
  for (uint32_t i = 0; sequence._buffer != nullptr && i < sequence._length; ++i) {
    strings.push_back(text(sequence._buffer[i]));
  }
  return strings;
}

}  // namespace dds
}  // namespace serial_robot_driver
