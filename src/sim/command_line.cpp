#include "serial_robot_driver/sim/command_line.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <iomanip>
#include <optional>
#include <sstream>
#include <vector>

#include "serial_robot_driver/sim/sim_device_module.h"
#include "serial_robot_driver/sim/sim_option_builders.h"

namespace serial_robot_driver::sim {

namespace {

/// One command-line flag: how it reads in --help and what it does to the options.
struct Flag {
  std::string name;        ///< "--seed"; empty: a section title in --help
  std::string value_name;  ///< "" for a switch
  std::string help;
  /// Applies the value ("" for a switch); returns "" or what is wrong with the value.
  std::function<std::string(const std::string& value, SimOptions& options)> apply;
  /// The default --help shows, read from a default SimOptions; empty: none shown.
  std::function<std::string(const SimOptions& defaults)> shown_default;
};

Flag section(const std::string& title) { return Flag{"", "", title, nullptr, nullptr}; }

/// A flag whose value is any text (a path).
Flag text(const std::string& name, const std::string& value_name, const std::string& help,
          std::string SimOptions::*field) {
  return Flag{name, value_name, help,
              [field](const std::string& value, SimOptions& options) {
                options.*field = value;
                return std::string();
              },
              nullptr};
}

/// A flag whose value is a number in [min, max].
Flag number(const std::string& name, const std::string& value_name, const std::string& help,
            double min, double max, double FaultOptions::*field, bool show_default = false) {
  std::function<std::string(const SimOptions&)> shown;
  if (show_default) shown = [field](const SimOptions& o) { return showDefault(o.faults.*field); };
  return Flag{name, value_name, help,
              [name, min, max, field](const std::string& value, SimOptions& options) {
                return option_detail::applyNumber(name, value, min, max, &(options.faults.*field));
              },
              shown};
}

Flag nonNegative(const std::string& name, const std::string& value_name, const std::string& help,
                 double FaultOptions::*field, bool show_default = false) {
  return number(name, value_name, help, 0.0, HUGE_VAL, field, show_default);
}

Flag probability(const std::string& name, const std::string& help, double FaultOptions::*field) {
  return number(name, "P", help, 0.0, 1.0, field);
}

/// A flag whose value is an unsigned integer up to `max`.
Flag whole(const std::string& name, const std::string& value_name, const std::string& help,
           uint64_t max, std::function<void(SimOptions&, uint64_t)> set,
           std::function<std::string(const SimOptions&)> shown_default) {
  return Flag{name, value_name, help,
              [name, max, set](const std::string& value, SimOptions& options) {
                uint64_t parsed = 0;
                std::string problem = option_detail::applyWhole(name, value, max, &parsed);
                if (problem.empty()) set(options, parsed);
                return problem;
              },
              shown_default};
}

/// The settings of `module`'s device, which a mention hosts when it is not hosted by default.
HostedDeviceOptions& mention(SimOptions& options, const SimDeviceModule& module) {
  HostedDeviceOptions& device = options.device(module.name);
  if (!module.hosted_by_default) device.enabled = true;
  return device;
}

std::string capitalized(std::string text) {
  if (!text.empty() && text[0] >= 'a' && text[0] <= 'z') text[0] = static_cast<char>(text[0] - 32);
  return text;
}

/// Every registered device's flags, one --help section per device: its own pty, the switch that
/// leaves it out (--no-<name>) or hosts it (--<name>), and the options it declares.
void addDeviceFlags(std::vector<Flag>* table) {
  for (const SimDeviceModule* module : registeredSimDevices()) {
    const std::string name = module->name;
    const bool by_default = module->hosted_by_default;
    table->push_back(section(capitalized(module->description) + " (" + name +
                             (by_default ? "" : "; not simulated unless asked for") + "):"));
    Flag link{linkFlag(*module), "PATH", module->link_help,
              [module](const std::string& value, SimOptions& o) {
                mention(o, *module).link = value;
                return std::string();
              },
              nullptr};
    Flag toggle{(by_default ? "--no-" : "--") + flagName(name), "", module->toggle_help,
                [module, by_default](const std::string&, SimOptions& o) {
                  mention(o, *module).enabled = !by_default;
                  return std::string();
                },
                nullptr};
    // As --help always listed them: a default device's pty first, an optional device's switch.
    if (by_default) {
      table->push_back(std::move(link));
      table->push_back(std::move(toggle));
    } else {
      table->push_back(std::move(toggle));
      table->push_back(std::move(link));
    }
    for (const SimDeviceOption& option : module->options) {
      Flag flag{optionFlag(*module, option), option.value_name, option.help, nullptr, nullptr};
      flag.apply = [module, option](const std::string& value, SimOptions& o) {
        HostedDeviceOptions& device = mention(o, *module);
        if (option.apply) return option.apply(value, device);
        device.settings[option.option] = value;
        return std::string();
      };
      if (option.shown_default) {
        flag.shown_default = [option](const SimOptions&) {
          return option.shown_default(HostedDeviceOptions{});
        };
      }
      table->push_back(std::move(flag));
    }
  }
}

/// Every flag of robot_sim, in --help order.
const std::vector<Flag>& flags() {
  static const std::vector<Flag> table = [] {
    std::vector<Flag> all{
        section("Ports:"),
        text("--link", "PATH", "symlink to the shared pty (default: none, just print the path)",
             &SimOptions::link),
        whole(
            "--pace-baud", "BAUD",
            "send and receive at most BAUD/10 bytes/s per port, like a real line (0 = pty speed)",
            4000000, [](SimOptions& o, uint64_t v) { o.pace_baud = static_cast<unsigned>(v); },
            [](const SimOptions& o) { return std::to_string(o.pace_baud); }),
    };
    addDeviceFlags(&all);
    for (Flag& flag : std::vector<Flag>{
             section("Faults (seeded):"),
             whole(
                 "--seed", "N", "random seed", 0xFFFFFFFFu,
                 [](SimOptions&o, uint64_t v) { o.faults.seed = static_cast<uint32_t>(v); },
                 [](const SimOptions&o) { return std::to_string(o.faults.seed); }),
             nonNegative("--garbage-rate", "HZ", "random junk bursts per second and port",
                         &FaultOptions::garbage_rate_hz),
             probability("--corrupt-rate", "probability a sent frame has its checksum byte flipped",
                         &FaultOptions::corrupt_rate),
             probability("--drop-rate", "probability a sent frame loses one byte",
                         &FaultOptions::drop_rate),
             nonNegative("--unplug-every", "S", "close the pty (and its link) every S seconds...",
                         &FaultOptions::unplug_every_s),
             nonNegative("--unplug-duration", "S",
                         "...for S seconds, then recreate it at the same link",
                         &FaultOptions::unplug_duration_s, true),
             section("Output:"),
             text("--stats-file", "PATH",
                  "\"key value\" counters, rewritten every second and at exit",
                  &SimOptions::stats_file),
         }) {
      all.push_back(std::move(flag));
    }
    return all;
  }();
  return table;
}

/// "--no-a, --no-b and --no-c": the switches that leave the default devices out.
std::string leaveOutFlags() {
  std::vector<std::string> names;
  for (const SimDeviceModule* module : registeredSimDevices()) {
    if (module->hosted_by_default) names.push_back("--no-" + flagName(module->name));
  }
  std::string joined;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) joined += i + 1 == names.size() ? " and " : ", ";
    joined += names[i];
  }
  return joined;
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
  std::string robot;  // what it simulates unless told otherwise
  for (const SimDeviceModule* module : registeredSimDevices()) {
    if (module->hosted_by_default)
      robot += (robot.empty() ? "" : ", ") + std::string(module->description);
  }
  out << "usage: robot_sim [options]\n"
         "A simulated robot ("
      << robot
      << ") on pseudo-terminal(s).\n"
         "Prints one line per pty: \"robot_sim: <devices> on <slave path> (link <link>)\".\n"
         "A link tcp://HOST:PORT (--link, --<device>-link) is served on a listening TCP socket\n"
         "instead of a pty, one client at a time, as a network serial server (ser2net) would;\n"
         "port 0 takes a free one (printed as the slave path). --unplug-every closes it.\n";
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
  const auto& modules = registeredSimDevices();
  const bool hosts_any = std::any_of(modules.begin(), modules.end(), [&](const SimDeviceModule* m) {
    return options.hosts(m->name);
  });
  if (!result.help && !hosts_any)
    return fail(leaveOutFlags() + " together leave nothing to simulate");
  return result;
}

}  // namespace serial_robot_driver::sim
