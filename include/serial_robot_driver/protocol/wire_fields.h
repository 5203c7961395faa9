// A frame's layout written once, as a list of fields: each field's name, wire type, byte order and
// unit, and the accessors that tie it to a record. Encoding, decoding and the sizes a command table
// or a length check needs all walk the same list, so no other code spells the bytes again.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>
#include <tuple>
#include <type_traits>
#include <utility>

namespace serial_robot_driver::protocol::wire {

enum class ByteOrder : uint8_t { kLittle, kBig };

struct WireType {
  uint8_t width;
  bool is_signed;
};
constexpr WireType kU8 = {1, false};
constexpr WireType kU16 = {2, false};
constexpr WireType kI16 = {2, true};
constexpr WireType kU32 = {4, false};
constexpr WireType kI32 = {4, true};
/// `width` reserved bytes: sent as zeros, ignored when read.
constexpr WireType reserved(uint8_t width) { return {width, false}; }

/// One field of a `Record`'s wire form. Values pass as int64_t: every wire type fits, and a value
/// wider than its field keeps its low bytes (two's complement for negative ones).
template <typename Record>
struct Field {
  std::string_view name;
  WireType type;
  ByteOrder order;
  std::string_view unit;  ///< one LSB: "0.1deg", "0.1deg/s", "deg/s", "ms", "mW"; "" raw
  int64_t (*get)(const Record&) = nullptr;  ///< nullptr: reserved bytes
  void (*set)(Record&, int64_t) = nullptr;  ///< nullptr: not kept when decoding
};

/// A view of a constexpr array of fields, so that lists of different lengths share one type.
template <typename Record>
struct FieldList {
  const Field<Record>* fields = nullptr;
  std::size_t count = 0;

  constexpr const Field<Record>* begin() const { return fields; }
  constexpr const Field<Record>* end() const { return fields + count; }
  /// Bytes on the wire.
  constexpr std::size_t size() const {
    std::size_t bytes = 0;
    for (const Field<Record>& field : *this) bytes += field.type.width;
    return bytes;
  }
  constexpr const Field<Record>* find(std::string_view name) const {
    for (const Field<Record>& field : *this) {
      if (field.name == name) return &field;
    }
    return nullptr;
  }
  constexpr bool has(std::string_view name) const { return find(name) != nullptr; }
  /// Byte offset of the field `name`, nullopt when the list has none.
  constexpr std::optional<std::size_t> offsetOf(std::string_view name) const {
    std::size_t offset = 0;
    for (const Field<Record>& field : *this) {
      if (field.name == name) return offset;
      offset += field.type.width;
    }
    return std::nullopt;
  }
};

template <typename Record, std::size_t N>
constexpr FieldList<Record> listOf(const std::array<Field<Record>, N>& fields) {
  return {fields.data(), N};
}

// --- accessors -------------------------------------------------------------------------------

template <auto kMember>
struct MemberTraits;
template <typename R, typename M, M R::*kMember>
struct MemberTraits<kMember> {
  using Record = R;
  using Type = M;
};

template <auto kMember>
int64_t getMember(const typename MemberTraits<kMember>::Record& record) {
  return static_cast<int64_t>(record.*kMember);
}
template <auto kMember>
void setMember(typename MemberTraits<kMember>::Record& record, int64_t value) {
  record.*kMember = static_cast<typename MemberTraits<kMember>::Type>(value);
}
template <auto kOuter, auto kInner>
int64_t getNested(const typename MemberTraits<kOuter>::Record& record) {
  return static_cast<int64_t>((record.*kOuter).*kInner);
}
template <auto kOuter, auto kInner>
void setNested(typename MemberTraits<kOuter>::Record& record, int64_t value) {
  (record.*kOuter).*kInner = static_cast<typename MemberTraits<kInner>::Type>(value);
}

/// A field stored in the record member `kMember`.
template <auto kMember>
constexpr Field<typename MemberTraits<kMember>::Record> field(std::string_view name, WireType type,
                                                              ByteOrder order,
                                                              std::string_view unit = {}) {
  return {name, type, order, unit, &getMember<kMember>, &setMember<kMember>};
}
/// A field stored in `record.*kOuter.*kInner` (a member of a member struct).
template <auto kOuter, auto kInner>
constexpr Field<typename MemberTraits<kOuter>::Record> nestedField(std::string_view name,
                                                                   WireType type, ByteOrder order,
                                                                   std::string_view unit = {}) {
  return {name, type, order, unit, &getNested<kOuter, kInner>, &setNested<kOuter, kInner>};
}
/// Reserved bytes of a `Record`'s layout.
template <typename Record>
constexpr Field<Record> reservedField(std::string_view name, uint8_t width) {
  return {name, reserved(width), ByteOrder::kLittle, {}, nullptr, nullptr};
}

// --- encode / decode -------------------------------------------------------------------------

inline void writeInteger(uint8_t* out, int64_t value, const WireType& type, ByteOrder order) {
  const auto bits = static_cast<uint64_t>(value);
  for (std::size_t i = 0; i < type.width; ++i) {
    const std::size_t shift = 8 * (order == ByteOrder::kLittle ? i : type.width - 1 - i);
    out[i] = static_cast<uint8_t>(bits >> shift);
  }
}

inline int64_t readInteger(const uint8_t* in, const WireType& type, ByteOrder order) {
  uint64_t bits = 0;
  for (std::size_t i = 0; i < type.width; ++i) {
    const std::size_t shift = 8 * (order == ByteOrder::kLittle ? i : type.width - 1 - i);
    bits |= static_cast<uint64_t>(in[i]) << shift;
  }
  const std::size_t unused = 64 - 8 * type.width;
  if (type.is_signed && unused > 0) {
    return static_cast<int64_t>(bits << unused) >> unused;  // sign-extend
  }
  return static_cast<int64_t>(bits);
}

/// Writes `record` as `fields` lays it out; `out` holds at least fields.size() bytes.
template <typename Record>
void encodeFields(FieldList<Record> fields, const Record& record, uint8_t* out) {
  for (const Field<Record>& field : fields) {
    writeInteger(out, field.get != nullptr ? field.get(record) : 0, field.type, field.order);
    out += field.type.width;
  }
}

/// Reads fields.size() bytes into the members of `record` the fields name.
template <typename Record>
void decodeFields(FieldList<Record> fields, const uint8_t* in, Record* record) {
  for (const Field<Record>& field : fields) {
    if (field.set != nullptr) field.set(*record, readInteger(in, field.type, field.order));
    in += field.type.width;
  }
}

// --- the same for a list known at compile time ------------------------------------------------
// For the per-frame hot paths (telemetry's servo records, sync-write targets): each field's
// accessor, wire type and offset are constants, so the compiler inlines the whole record instead of
// walking the list through function pointers. Same bytes, same values as decodeFields().

namespace detail {

template <const auto& kFields, std::size_t I>
constexpr std::size_t offsetOfIndex() {
  std::size_t offset = 0;
  for (std::size_t k = 0; k < I; ++k) offset += kFields[k].type.width;
  return offset;
}

template <const auto& kFields, std::size_t I, typename Record>
void decodeOne(const uint8_t* in, Record* record) {
  if constexpr (kFields[I].set != nullptr) {
    constexpr std::size_t kOffset = offsetOfIndex<kFields, I>();
    constexpr WireType kType = kFields[I].type;
    constexpr ByteOrder kOrder = kFields[I].order;
    kFields[I].set(*record, readInteger(in + kOffset, kType, kOrder));
  }
}

template <const auto& kFields, typename Record, std::size_t... I>
void decodeAll(const uint8_t* in, Record* record, std::index_sequence<I...>) {
  (decodeOne<kFields, I>(in, record), ...);
}

}  // namespace detail

/// decodeFields() of a constexpr std::array of fields with static storage (a namespace-scope list).
template <const auto& kFields, typename Record>
void decodeFieldsStatic(const uint8_t* in, Record* record) {
  constexpr std::size_t kCount = std::tuple_size_v<std::decay_t<decltype(kFields)>>;
  detail::decodeAll<kFields>(in, record, std::make_index_sequence<kCount>{});
}

}  // namespace serial_robot_driver::protocol::wire
