#include "serial_robot_driver/params/param_table.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

#include "serial_robot_driver/transport/serial_port.h"
#include "serial_robot_driver/transport/tcp_stream.h"

namespace serial_robot_driver::params {

namespace {

template <typename T>
constexpr bool kScalar = std::is_same_v<T, bool> || std::is_same_v<T, int> ||
                         std::is_same_v<T, double> || std::is_same_v<T, std::string>;

/// The dot-separated parts of a host ("10.0.0.1" -> 10, 0, 0, 1); an empty part stays empty.
std::vector<std::string> hostLabels(const std::string& host) {
  std::vector<std::string> labels(1);
  for (const char c : host) {
    if (c == '.') {
      labels.emplace_back();
    } else {
      labels.back() += c;
    }
  }
  return labels;
}

bool allDigits(const std::string& text) {
  return !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
}

/// Why `host` is neither an IPv4 address nor an RFC 1123 host name, or "" when it is one.
std::string hostProblem(const std::string& host) {
  const std::vector<std::string> labels = hostLabels(host);
  if (std::all_of(labels.begin(), labels.end(), allDigits)) {  // numbers: it must be an address
    const bool address = labels.size() == 4 &&
                         std::all_of(labels.begin(), labels.end(), [](const std::string& part) {
                           return part.size() <= 3 && std::stoi(part) <= 255;
                         });
    return address ? "" : "is not an IPv4 address (a.b.c.d, each 0..255)";
  }
  if (host.size() > 253) return "is longer than a host name may be (253 characters)";
  for (const std::string& label : labels) {
    const bool ok = !label.empty() && label.size() <= 63 && label.front() != '-' &&
                    label.back() != '-' && std::all_of(label.begin(), label.end(), [](char c) {
                      return std::isalnum(static_cast<unsigned char>(c)) || c == '-';
                    });
    if (!ok) return "is neither an IPv4 address nor a host name (letters, digits, '-', '.')";
  }
  return "";
}

std::string numberText(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

}  // namespace

std::string typeName(const ParamValue& value) {
  static const char* const kNames[] = {
      "true or false",      "an integer",        "a number",         "a string",
      "a list of integers", "a list of strings", "a list of numbers"};
  return kNames[value.index()];
}

std::string toText(const ParamValue& value) {
  std::ostringstream text;
  std::visit(
      [&text](const auto& typed) {
        using T = std::decay_t<decltype(typed)>;
        if constexpr (std::is_same_v<T, bool>) {
          text << (typed ? "true" : "false");
        } else if constexpr (std::is_same_v<T, std::string>) {
          text << '"' << typed << '"';
        } else if constexpr (kScalar<T>) {
          text << typed;
        } else {
          text << '[';
          for (std::size_t i = 0; i < typed.size(); ++i) text << (i ? ", " : "") << typed[i];
          text << ']';
        }
      },
      value);
  return text.str();
}

void require(bool ok, const std::string& key, const std::string& problem) {
  if (!ok) throw ParameterError(key, problem);
}

void positiveNumber(const double& value, const std::string& key) {
  require(std::isfinite(value) && value > 0, key,
          "must be a finite number > 0 (got " + numberText(value) + ")");
}

void positiveInteger(const int& value, const std::string& key) {
  require(value > 0, key, "must be a finite number > 0 (got " + std::to_string(value) + ")");
}

void nonNegativeNumber(const double& value, const std::string& key) {
  require(std::isfinite(value) && value >= 0, key,
          "must be a finite number >= 0 (got " + numberText(value) + ")");
}

void finiteNumber(const double& value, const std::string& key) {
  require(std::isfinite(value), key, "must be finite");
}

void percent(const int& value, const std::string& key) {
  require(value >= 0 && value <= 100, key, "must be 0..100 (got " + std::to_string(value) + ")");
}

void direction(const int& value, const std::string& key) {
  require(
      value == 1 || value == -1, key,
      "must be 1 or -1 (got " + std::to_string(value) + "); -1 flips a wheel that drives backward");
}

void directionList(const std::vector<int>& values, const std::string& key) {
  for (int d : values) require(d == 1 || d == -1, key, "entries must be 1 or -1");
}

void frameId(const std::string& value, const std::string& key) {
  require(!value.empty(), key, "must name a tf frame");
  require(value.find(' ') == std::string::npos, key, "must not contain spaces");
}

void uniqueNames(const std::vector<std::string>& names, const std::string& key) {
  std::set<std::string> seen;
  for (const auto& name : names) {
    require(!name.empty(), key, "a joint name is empty");
    require(seen.insert(name).second, key, "'" + name + "' is listed twice");
  }
}

void networkHosts(const std::vector<std::string>& hosts, const std::string& key) {
  std::set<std::string> seen;
  for (const auto& host : hosts) {
    const std::string problem = hostProblem(host);
    require(problem.empty(), key, "'" + host + "' " + problem);
    require(seen.insert(host).second, key, "'" + host + "' is listed twice");
  }
}

void portPath(const std::string& value, const std::string& key) {
  require(!value.empty(), key, "must name a serial device, e.g. /dev/ttyUSB0");
  if (!transport::isTcpUrl(value)) return;
  std::string problem;
  if (!transport::parseTcpUrl(value, &problem)) {
    constexpr std::size_t kLongestQuoted = 80;  // a hostile value must not flood the log
    const std::string shown =
        value.size() <= kLongestQuoted ? value : value.substr(0, kLongestQuoted) + "...";
    require(false, key, shown + ": " + problem);
  }
}

void portOrInherit(const std::string& value, const std::string& key) {
  if (!value.empty()) portPath(value, key);
}

void baudRate(const int& value, const std::string& key) {
  // The port's own table: a rate passes here exactly when the port can open at it.
  require(value > 0 && transport::isSupportedBaud(static_cast<unsigned>(value)), key,
          "unsupported baud rate " + std::to_string(value) +
              " (supported: " + transport::supportedBaudRatesText() + ")");
}

void baudOrInherit(const int& value, const std::string& key) {
  if (value != 0) baudRate(value, key);
}

Rule<int> integerWithin(int low, int high, const std::string& unit) {
  return [low, high, unit](const int& value, const std::string& key) {
    require(value >= low && value <= high, key,
            "must be " + std::to_string(low) + ".." + std::to_string(high) +
                (unit.empty() ? "" : " " + unit));
  };
}

Rule<double> numberWithin(double low, double high, const std::string& unit) {
  return [low, high, unit](const double& value, const std::string& key) {
    require(
        std::isfinite(value) && value >= low && value <= high, key,
        "must be " + numberText(low) + ".." + numberText(high) + (unit.empty() ? "" : " " + unit));
  };
}

const ParamSpec& specFor(const std::string& key) {
  for (const ParamSpec& spec : parameterTable()) {
    if (spec.key == key) return spec;
  }
  throw std::invalid_argument("no parameter ~" + key + " in the table");
}

}  // namespace serial_robot_driver::params
