// A value whose type the shared plumbing does not know but its owner does: a device's parameter
// section (params/device_sections.h), its simulator settings and counters
// (sim/sim_device_module.h). Copies clone the value; reading it as any other type than the one
// stored is a programming error and throws std::logic_error (no silent empty result).
#pragma once

#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>

namespace serial_robot_driver::core {

class TypedValue {
 public:
  TypedValue() = default;
  /// Holds `value` (implicit, so a struct of counters can be given where a TypedValue is wanted).
  template <typename T, typename = std::enable_if_t<!std::is_same_v<std::decay_t<T>, TypedValue>>>
  TypedValue(T&& value)  // NOLINT(google-explicit-constructor)
      : holder_(std::make_unique<HolderOf<std::decay_t<T>>>(std::forward<T>(value))) {}

  TypedValue(const TypedValue& other) : holder_(other.holder_ ? other.holder_->clone() : nullptr) {}
  TypedValue& operator=(const TypedValue& other) {
    if (this != &other) holder_ = other.holder_ ? other.holder_->clone() : nullptr;
    return *this;
  }
  TypedValue(TypedValue&&) noexcept = default;
  TypedValue& operator=(TypedValue&&) noexcept = default;

  bool empty() const { return holder_ == nullptr; }
  template <typename T>
  bool holds() const {
    return holdsType(typeid(T));
  }
  bool holdsType(const std::type_info& type) const {
    return holder_ != nullptr && holder_->type() == type;
  }

  /// The value; throws std::logic_error when it is empty or of another type.
  template <typename T>
  T& as() {
    requireType(typeid(T));
    return static_cast<HolderOf<T>&>(*holder_).value;
  }
  template <typename T>
  const T& as() const {
    requireType(typeid(T));
    return static_cast<const HolderOf<T>&>(*holder_).value;
  }

 private:
  struct Holder {
    virtual ~Holder() = default;
    virtual std::unique_ptr<Holder> clone() const = 0;
    virtual const std::type_info& type() const = 0;
  };
  template <typename T>
  struct HolderOf final : Holder {
    explicit HolderOf(T v) : value(std::move(v)) {}
    std::unique_ptr<Holder> clone() const override { return std::make_unique<HolderOf>(value); }
    const std::type_info& type() const override { return typeid(T); }
    T value;
  };

  void requireType(const std::type_info& type) const {
    if (holder_ == nullptr) {
      throw std::logic_error(std::string("a typed value read as ") + type.name() +
                             " holds nothing");
    }
    if (holder_->type() != type) {
      throw std::logic_error(std::string("a typed value of ") + holder_->type().name() +
                             " read as " + type.name());
    }
  }

  std::unique_ptr<Holder> holder_;
};

}  // namespace serial_robot_driver::core
