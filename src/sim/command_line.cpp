#include "serial_robot_driver/sim/command_line.h"

#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <iomanip>
#include <map>
#include <optional>
#include <sstream>
#include <vector>

#include "serial_robot_driver/devices/body/body_codec.h"
#include "serial_robot_driver/sim/sim_device_module.h"

namespace serial_robot_driver::sim {

namespace {

bool parseDouble(const std::string& text, double* value) {
  char* end = nullptr;
  errno = 0;
  const double parsed = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || errno != 0 || !std::isfinite(parsed)) return false;
  *value = parsed;
  return true;
}

bool parseUnsigned(const std::string& text, uint64_t max, uint64_t* value) {
  if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos) return false;
  errno = 0;
  const unsigned long long parsed = std::strtoull(text.c_str(), nullptr, 10);
  if (errno != 0 || parsed > max) return false;
  *value = parsed;
  return true;
}

bool parseIdList(const std::string& text, std::vector<uint8_t>* ids) {
  ids->clear();
  std::stringstream stream(text);
  std::string item;
  while (std::getline(stream, item, ',')) {
    uint64_t id = 0;
    if (!parseUnsigned(item, 254, &id)) return false;
    ids->push_back(static_cast<uint8_t>(id));
  }
  return true;
}

template <typename T>
std::string show(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

std::string show(const std::vector<uint8_t>& ids) {
  std::string text;
  for (uint8_t id : ids) text += (text.empty() ? "" : ",") + std::to_string(id);
  return text;
}

/// One command-line flag: how it reads in --help and what it does to the options.
struct Flag {
  std::string name;        ///< "--battery"; empty: a section title in --help
  std::string value_name;  ///< "" for a switch
  std::string help;
  /// Applies the value ("" for a switch); returns "" or what is wrong with the value.
  std::function<std::string(const std::string& value, SimOptions& options)> apply;
  /// The default --help shows, read from a default SimOptions; empty: none shown.
  std::function<std::string(const SimOptions& defaults)> shown_default;
};

Flag section(const std::string& title) { return Flag{"", "", title, nullptr, nullptr}; }

Flag toggle(const std::string& name, const std::string& help,
            std::function<void(SimOptions&)> set) {
  return Flag{name, "", help,
              [set](const std::string&, SimOptions& options) {
                set(options);
                return std::string();
              },
              nullptr};
}

/// A flag whose value is any text (a path).
template <typename Text>  // std::string or std::optional<std::string>
Flag text(const std::string& name, const std::string& value_name, const std::string& help,
          Text SimOptions::*field) {
  return Flag{name, value_name, help,
              [field](const std::string& value, SimOptions& options) {
                options.*field = value;
                return std::string();
              },
              nullptr};
}

std::string badValue(const std::string& name, const std::string& value) {
  return "bad value for " + name + ": '" + value + "'";
}

/// A flag whose value is a number in [min, max].
Flag number(const std::string& name, const std::string& value_name, const std::string& help,
            double min, double max, std::function<double&(SimOptions&)> field,
            std::function<std::string(const SimOptions&)> shown_default = nullptr) {
  return Flag{name, value_name, help,
              [name, min, max, field](const std::string& value, SimOptions& options) {
                double parsed = 0;
                if (!parseDouble(value, &parsed) || parsed < min || parsed > max) {
                  return badValue(name, value);
                }
                field(options) = parsed;
                return std::string();
              },
              shown_default};
}

Flag nonNegative(const std::string& name, const std::string& value_name, const std::string& help,
                 std::function<double&(SimOptions&)> field, bool show_default = false) {
  std::function<std::string(const SimOptions&)> shown;
  if (show_default)
    shown = [field](const SimOptions& o) { return show(field(const_cast<SimOptions&>(o))); };
  return number(name, value_name, help, 0.0, HUGE_VAL, field, shown);
}

Flag probability(const std::string& name, const std::string& help,
                 std::function<double&(SimOptions&)> field) {
  return number(name, "P", help, 0.0, 1.0, field);
}

/// A flag whose value is an unsigned integer up to `max`.
Flag whole(const std::string& name, const std::string& value_name, const std::string& help,
           uint64_t max, std::function<void(SimOptions&, uint64_t)> set,
           std::function<std::string(const SimOptions&)> shown_default) {
  return Flag{name, value_name, help,
              [name, max, set](const std::string& value, SimOptions& options) {
                uint64_t parsed = 0;
                if (!parseUnsigned(value, max, &parsed)) return badValue(name, value);
                set(options, parsed);
                return std::string();
              },
              shown_default};
}

/// A flag whose value is a comma-separated list of servo ids; `max_count` is what a telemetry
/// frame holds (SIZE_MAX for lists that do not go into telemetry).
Flag idList(const std::string& name, const std::string& value_name, const std::string& help,
            std::size_t max_count, std::function<std::vector<uint8_t>&(SimOptions&)> field,
            bool show_default) {
  std::function<std::string(const SimOptions&)> shown;
  if (show_default)
    shown = [field](const SimOptions& o) { return show(field(const_cast<SimOptions&>(o))); };
  return Flag{name, value_name, help,
              [name, max_count, field](const std::string& value, SimOptions& options) {
                std::vector<uint8_t>& ids = field(options);
                if (!parseIdList(value, &ids)) {
                  return badValue(name, value) + " (comma-separated ids 0..254)";
                }
                if (ids.size() > max_count) {
                  return "too many " + name + " (at most " + std::to_string(max_count) +
                         " fit in a telemetry frame)";
                }
                return std::string();
              },
              shown};
}

/// "ID:VALUE" into a per-servo map (a bus servo's held temperature or voltage); repeatable.
Flag heldValue(const std::string& name, const std::string& value_name, const std::string& help,
               std::function<std::map<uint8_t, int64_t>&(SimOptions&)> field) {
  return Flag{name, value_name, help,
              [name, field](const std::string& value, SimOptions& options) {
                const std::size_t colon = value.find(':');
                std::vector<uint8_t> ids;
                double number = 0;
                if (colon == std::string::npos || !parseIdList(value.substr(0, colon), &ids) ||
                    ids.size() != 1 || !parseDouble(value.substr(colon + 1), &number) ||
                    number < 0 || number > 65535) {
                  return badValue(name, value) + " (ID:VALUE, id 0..254, value 0..65535)";
                }
                field(options)[ids.front()] = static_cast<int64_t>(number);
                return std::string();
              },
              {}};
}

/// The hosted device `name` in `options`, added on first mention.
HostedDeviceOptions& hostedDevice(SimOptions& options, const std::string& name) {
  for (HostedDeviceOptions& hosted : options.hosted) {
    if (hosted.name == name) return hosted;
  }
  options.hosted.push_back(HostedDeviceOptions{name, std::nullopt, {}});
  return options.hosted.back();
}

/// The flags of every registered device robot_sim hosts through its SimDeviceModule (none of the
/// built-in ones): --<name> hosts it, --<name>-link and --<name>-<option> too, with that setting.
std::vector<Flag> withHostedDevices(std::vector<Flag> table) {
  bool titled = false;
  for (const SimDeviceModule* module : registeredSimDevices()) {
    if (module->make == nullptr) continue;
    if (!titled) table.push_back(section("Other devices (none unless asked for):"));
    titled = true;
    const std::string name = module->name;
    const std::string flag = "--" + flagName(name);
    table.push_back(toggle(flag, "simulate the " + name + " device (on the shared pty)",
                           [name](SimOptions& o) { hostedDevice(o, name); }));
    table.push_back(Flag{flag + "-link", "PATH", "own pty for the " + name + " device (hosts it)",
                         [name](const std::string& value, SimOptions& o) {
                           hostedDevice(o, name).link = value;
                           return std::string();
                         },
                         nullptr});
    for (const SimDeviceOption& option : module->options) {
      const std::string key = option.option;
      table.push_back(Flag{flag + "-" + key, option.value_name, option.help,
                           [name, key](const std::string& value, SimOptions& o) {
                             hostedDevice(o, name).settings[key] = value;
                             return std::string();
                           },
                           nullptr});
    }
  }
  return table;
}

/// Every flag of robot_sim, in --help order.
const std::vector<Flag>& flags() {
  static const std::vector<Flag> table = withHostedDevices({
      section("Ports:"),
      text("--link", "PATH", "symlink to the shared pty (default: none, just print the path)",
           &SimOptions::link),
      text("--base-link", "PATH", "own pty for the base (devices naming the same link share a pty)",
           &SimOptions::base_link),
      text("--body-link", "PATH", "own pty for the servo controller board", &SimOptions::body_link),
      text("--servo-link", "PATH", "own pty for the servo bus", &SimOptions::servo_link),
      toggle("--no-base", "leave the base out", [](SimOptions& o) { o.enable_base = false; }),
      toggle("--no-body", "leave the servo controller board out",
             [](SimOptions& o) { o.enable_body = false; }),
      toggle("--no-servo-bus", "leave the servo bus out",
             [](SimOptions& o) { o.enable_servo_bus = false; }),

      section("Devices:"),
      whole(
          "--battery", "PCT", "battery percent the base reports", 100,
          [](SimOptions& o, uint64_t v) { o.base.battery_percent = static_cast<uint8_t>(v); },
          [](const SimOptions& o) { return show(static_cast<int>(o.base.battery_percent)); }),
      idList(
          "--servo-ids", "1,2", "body servo ids in telemetry order",
          protocol::body::kMaxTelemetryServos,
          [](SimOptions& o) -> std::vector<uint8_t>& { return o.body.servo_ids; }, true),
      nonNegative(
          "--telemetry-rate", "HZ", "telemetry frames per second (0 = off)",
          [](SimOptions& o) -> double& { return o.body.telemetry_rate_hz; }, true),
      toggle("--foot", "every telemetry frame carries the foot block",
             [](SimOptions& o) { o.body.foot_mode = FootMode::kAlways; }),
      toggle("--foot-alternate", "every other telemetry frame carries it",
             [](SimOptions& o) { o.body.foot_mode = FootMode::kAlternate; }),
      nonNegative(
          "--servo-speed", "TICKS_S", "body servo speed bound in ticks/s",
          [](SimOptions& o) -> double& { return o.body.servo_speed; }, true),
      toggle("--imu-noise", "+-2 LSB noise on the IMU values",
             [](SimOptions& o) { o.body.imu_noise = true; }),
      Flag{"--gyro-bias", "X,Y,Z", "rad/s added to the gyro's sensor axes",
           [](const std::string& value, SimOptions& o) {
             const auto bias = parseGyroBias(value);
             if (bias) o.body.gyro_bias = *bias;
             return bias ? std::string() : badValue("--gyro-bias", value) + " (X,Y,Z in rad/s)";
           },
           [](const SimOptions& o) {
             const auto& b = o.body.gyro_bias;
             return show(b[0]) + "," + show(b[1]) + "," + show(b[2]);
           }},
      number(
          "--turn-slip", "FRACTION",
          "wheel slip: the base turns by (1 - FRACTION) of the commanded yaw rate (0..1); the IMU "
          "reports the true turn",
          0.0, 1.0, [](SimOptions& o) -> double& { return o.base.turn_slip; }),
      idList(
          "--bus-servo-ids", "0,1,2", "ids on the servo bus", SIZE_MAX,
          [](SimOptions& o) -> std::vector<uint8_t>& { return o.servo_bus.servo_ids; }, true),
      idList(
          "--offline-ids", "7", "ids that never answer", SIZE_MAX,
          [](SimOptions& o) -> std::vector<uint8_t>& { return o.servo_bus.offline_ids; }, false),
      heldValue(
          "--servo-temperature", "ID:DEGC", "hold a bus servo's temperature at DEGC (repeatable)",
          [](SimOptions& o) -> std::map<uint8_t, int64_t>& { return o.servo_bus.temperature_c; }),
      heldValue(
          "--servo-voltage", "ID:MV", "hold a bus servo's voltage at MV (repeatable)",
          [](SimOptions& o) -> std::map<uint8_t, int64_t>& { return o.servo_bus.voltage_mv; }),
      heldValue(
          "--servo-type", "ID:TYPE", "a bus servo's servo_type (repeatable; otherwise 257)",
          [](SimOptions& o) -> std::map<uint8_t, int64_t>& { return o.servo_bus.servo_type; }),
      heldValue("--servo-firmware", "ID:VERSION",
                "a bus servo's firmware_version (repeatable; otherwise 258)",
                [](SimOptions& o) -> std::map<uint8_t, int64_t>& {
                  return o.servo_bus.firmware_version;
                }),
      heldValue(
          "--servo-response-switch", "ID:0|1",
          "a bus servo's response_switch (repeatable; otherwise 0)",
          [](SimOptions& o) -> std::map<uint8_t, int64_t>& { return o.servo_bus.response_switch; }),
      Flag{"--servo-latency-ms", "MS", "servo bus answer latency",
           [](const std::string& value, SimOptions& o) {
             double ms = 0;
             if (!parseDouble(value, &ms) || ms < 0) return badValue("--servo-latency-ms", value);
             o.servo_bus.answer_latency_s = ms / 1000.0;
             return std::string();
           },
           [](const SimOptions& o) { return show(o.servo_bus.answer_latency_s * 1000.0); }},

      whole(
          "--pace-baud", "BAUD",
          "send and receive at most BAUD/10 bytes/s per port, like a real line (0 = pty speed)",
          4000000, [](SimOptions& o, uint64_t v) { o.pace_baud = static_cast<unsigned>(v); },
          [](const SimOptions& o) { return show(o.pace_baud); }),

      section("Faults (seeded):"),
      whole(
          "--seed", "N", "random seed", 0xFFFFFFFFu,
          [](SimOptions& o, uint64_t v) { o.faults.seed = static_cast<uint32_t>(v); },
          [](const SimOptions& o) { return show(o.faults.seed); }),
      nonNegative("--garbage-rate", "HZ", "random junk bursts per second and port",
                  [](SimOptions& o) -> double& { return o.faults.garbage_rate_hz; }),
      probability("--corrupt-rate", "probability a sent frame has its checksum byte flipped",
                  [](SimOptions& o) -> double& { return o.faults.corrupt_rate; }),
      probability("--drop-rate", "probability a sent frame loses one byte",
                  [](SimOptions& o) -> double& { return o.faults.drop_rate; }),
      nonNegative("--unplug-every", "S", "close the pty (and its link) every S seconds...",
                  [](SimOptions& o) -> double& { return o.faults.unplug_every_s; }),
      nonNegative(
          "--unplug-duration", "S", "...for S seconds, then recreate it at the same link",
          [](SimOptions& o) -> double& { return o.faults.unplug_duration_s; }, true),
      probability("--servo-fault-rate", "probability a servo answer is garbled or missing",
                  [](SimOptions& o) -> double& { return o.faults.servo_fault_rate; }),
      whole(
          "--lose-servo-stops", "N",
          "the next N SPIN stops to a bus servo are lost on the line: the servo keeps moving",
          1000000,
          [](SimOptions& o, uint64_t v) { o.servo_bus.lost_stops = static_cast<uint32_t>(v); },
          [](const SimOptions& o) { return show(o.servo_bus.lost_stops); }),

      section("Output:"),
      text("--stats-file", "PATH", "\"key value\" counters, rewritten every second and at exit",
           &SimOptions::stats_file),
  });
  return table;
}

const Flag* findFlag(const std::string& name) {
  for (const Flag& flag : flags()) {
    if (!flag.name.empty() && flag.name == name) return &flag;
  }
  return nullptr;
}

}  // namespace

std::string usage() {
  std::ostringstream out;
  out << "usage: robot_sim [options]\n"
         "A simulated robot (AP1 base, servo controller board, UART bus servos) on "
         "pseudo-terminal(s).\n"
         "Prints one line per pty: \"robot_sim: <devices> on <slave path> (link <link>)\".\n";
  const SimOptions defaults;
  const auto row = [&out](const std::string& left, const std::string& help) {
    out << "  " << std::left << std::setw(22) << left << (left.size() < 22 ? "  " : " ") << help
        << '\n';
  };
  for (const Flag& flag : flags()) {
    if (flag.name.empty()) {
      out << '\n' << flag.help << '\n';
      continue;
    }
    std::string help = flag.help;
    if (flag.shown_default) help += " (default " + flag.shown_default(defaults) + ")";
    row(flag.name + (flag.value_name.empty() ? "" : " " + flag.value_name), help);
  }
  row("--help, -h", "this text");
  out << "\nArguments containing \":=\" (roslaunch's __name:=..., __log:=...) are ignored.\n";
  return out.str();
}

CommandLine parseCommandLine(int argc, const char* const* argv) {
  CommandLine result;
  std::vector<std::string> args;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.find(":=") != std::string::npos) continue;  // roslaunch remapping / special args
    args.push_back(arg);
  }

  const auto fail = [&result](const std::string& message) {
    result.error = message;
    return result;
  };
  for (std::size_t i = 0; i < args.size(); ++i) {
    std::string name = args[i];
    std::optional<std::string> inline_value;
    const std::size_t equals = name.find('=');
    if (name.rfind("--", 0) == 0 && equals != std::string::npos) {
      inline_value = name.substr(equals + 1);
      name = name.substr(0, equals);
    }
    if (name == "--help" || name == "-h") {
      if (inline_value) return fail(name + " takes no value");
      result.help = true;
      continue;
    }
    const Flag* flag = findFlag(name);
    if (!flag) return fail("unknown argument: " + args[i]);

    std::string value;
    if (flag->value_name.empty()) {
      if (inline_value) return fail(name + " takes no value");
    } else if (inline_value) {
      value = *inline_value;
    } else if (i + 1 < args.size()) {
      value = args[++i];
    } else {
      return fail("missing value for " + name);
    }
    const std::string problem = flag->apply(value, result.options);
    if (!problem.empty()) return fail(problem);
  }
  const SimOptions& options = result.options;
  if (!result.help && !options.enable_base && !options.enable_body && !options.enable_servo_bus &&
      options.hosted.empty()) {
    return fail("--no-base, --no-body and --no-servo-bus together leave nothing to simulate");
  }
  return result;
}

}  // namespace serial_robot_driver::sim
