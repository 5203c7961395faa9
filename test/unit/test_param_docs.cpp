// The parameter documentation against the parameter table: docs/node_api.md's parameter tables
// list exactly the table's keys with the table's defaults, and config/robot.yaml uses only keys
// of the table. The table is the one place a parameter is defined; these tests keep the two texts
// a user reads in step with it.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "serial_robot_driver/params/driver_params.h"

namespace serial_robot_driver::params {
namespace {

const std::string kSourceDir = SRD_SOURCE_DIR;

/// Documented under "## Parameters" but read outside the table, as the doc says of each.
const std::set<std::string> kDocumentedOutsideTheTable{"diagnostic_period", "tf_prefix"};

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

std::vector<std::string> split(const std::string& text, const std::string& separator) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (std::size_t at; (at = text.find(separator, start)) != std::string::npos;) {
    parts.push_back(text.substr(start, at - start));
    start = at + separator.size();
  }
  parts.push_back(text.substr(start));
  return parts;
}

std::string withoutBackticks(const std::string& text) {
  std::string out;
  for (const char c : text) {
    if (c != '`') out += c;
  }
  return trim(out);
}

/// One documented parameter: its key as in the table and the text of its default column.
struct DocumentedParam {
  std::string key;
  std::string default_text;
  std::string file;
  int line;
};

/// The rows of the parameter tables under "## Parameters" in `path` (docs/node_api.md, or a device
/// folder's README.md: a device that is not one of the robot's own documents itself). A section
/// "### ... (`~<prefix>/`)" names its rows' prefix; "### General" has none (its names carry the
/// `~`). A row's first cell may list several parameters ("`port` / `baud`"); its default cell
/// then lists their defaults in the same order, separated the same way.
std::vector<DocumentedParam> documentedParamsIn(const std::string& path) {
  std::ifstream file(kSourceDir + "/" + path);
  EXPECT_TRUE(file.good()) << path;
  std::vector<DocumentedParam> documented;
  bool in_parameters = false;
  std::string prefix;
  int default_column = -1;
  std::string line;
  for (int number = 1; std::getline(file, line); ++number) {
    if (line.rfind("## ", 0) == 0) {
      in_parameters = line == "## Parameters";
      continue;
    }
    if (!in_parameters) continue;
    if (line.rfind("### ", 0) == 0) {
      const auto open = line.find("(`~");
      prefix = open == std::string::npos ? "" : line.substr(open + 3, line.find("`)") - open - 3);
      default_column = -1;
      continue;
    }
    if (line.rfind("|", 0) != 0 || line.rfind("|---", 0) == 0) continue;
    std::vector<std::string> cells = split(line, "|");
    cells = std::vector<std::string>(cells.begin() + 1, cells.end() - 1);  // outside the pipes
    for (auto& cell : cells) cell = trim(cell);
    if (cells.front() == "parameter") {  // the header row says where the default is
      default_column = -1;
      for (std::size_t i = 0; i < cells.size(); ++i) {
        if (cells[i] == "default") default_column = static_cast<int>(i);
      }
      continue;
    }
    EXPECT_GE(default_column, 0) << path << ":" << number << ": a table without a default";
    if (default_column < 0) continue;
    const std::vector<std::string> names = split(cells.front(), " / ");
    std::vector<std::string> defaults = split(cells[default_column], " / ");
    if (defaults.size() != names.size()) defaults = std::vector<std::string>(names.size(), "");
    for (std::size_t i = 0; i < names.size(); ++i) {
      std::string name = withoutBackticks(names[i]);
      if (name.rfind("~", 0) == 0) name = name.substr(1);
      documented.push_back({prefix + name, withoutBackticks(defaults[i]), path, number});
    }
  }
  return documented;
}

/// docs/node_api.md's parameters and those of every device folder's README.md.
std::vector<DocumentedParam> documentedParams() {
  std::vector<DocumentedParam> documented = documentedParamsIn("docs/node_api.md");
  std::vector<std::string> readmes;
  for (const auto& entry : std::filesystem::directory_iterator(kSourceDir + "/src/devices")) {
    if (std::filesystem::exists(entry.path() / "README.md")) {
      readmes.push_back("src/devices/" + entry.path().filename().string() + "/README.md");
    }
  }
  std::sort(readmes.begin(), readmes.end());
  for (const std::string& readme : readmes) {
    const std::vector<DocumentedParam> more = documentedParamsIn(readme);
    documented.insert(documented.end(), more.begin(), more.end());
  }
  return documented;
}

/// Half a unit of the last decimal the doc writes: "0.0047884" stands for 0.00478840 ± 5e-8.
double roundingOf(const std::string& number) {
  const auto point = number.find('.');
  if (point == std::string::npos || number.find_first_of("eE") != std::string::npos) return 0.0;
  return 0.5 * std::pow(10.0, -static_cast<double>(number.size() - point - 1));
}

/// Whether the doc's default text states `value`. The text is read as the table's type: `""` is
/// the empty string, any other text a string's value itself; true/false; an integer; a number
/// equal to the value as far as the doc writes its digits; a list in brackets with its entries
/// separated by ", " (entries read as the list's type, unquoted strings).
bool statesDefault(const std::string& text, const ParamValue& value) {
  const auto number_equals = [](const std::string& written, double expected) {
    std::size_t used = 0;
    const double read = std::stod(written, &used);
    return used == written.size() &&
           std::abs(read - expected) <= roundingOf(written) + 1e-12 * std::abs(expected);
  };
  const auto entries = [&text]() -> std::vector<std::string> {
    if (text.size() < 2 || text.front() != '[' || text.back() != ']') return {"<not a list>"};
    const std::string inside = text.substr(1, text.size() - 2);
    return inside.empty() ? std::vector<std::string>{} : split(inside, ", ");
  };
  try {
    if (const auto* b = std::get_if<bool>(&value)) return text == (*b ? "true" : "false");
    if (const auto* i = std::get_if<int>(&value)) return text == std::to_string(*i);
    if (const auto* d = std::get_if<double>(&value)) return number_equals(text, *d);
    if (const auto* s = std::get_if<std::string>(&value)) return text == (s->empty() ? "\"\"" : *s);
    const std::vector<std::string> written = entries();
    if (const auto* list = std::get_if<std::vector<int>>(&value)) {
      std::vector<std::string> expected;
      for (const int entry : *list) expected.push_back(std::to_string(entry));
      return written == expected;
    }
    if (const auto* list = std::get_if<std::vector<std::string>>(&value)) return written == *list;
    const auto& list = std::get<std::vector<double>>(value);
    if (written.size() != list.size()) return false;
    for (std::size_t i = 0; i < list.size(); ++i) {
      if (!number_equals(written[i], list[i])) return false;
    }
    return true;
  } catch (const std::logic_error&) {  // std::stod on a text that is no number
    return false;
  }
}

TEST(ParameterDocs, NodeApiDocumentsEveryKeyOfTheTableAndNoOther) {
  std::set<std::string> documented;
  for (const DocumentedParam& param : documentedParams()) {
    EXPECT_TRUE(documented.insert(param.key).second)
        << "~" << param.key << " documented twice (" << param.file << ":" << param.line << ")";
  }
  std::set<std::string> in_table;
  for (const ParamSpec& spec : parameterTable()) {
    in_table.insert(spec.key);
    EXPECT_EQ(documented.count(spec.key), 1u)
        << "~" << spec.key << " is not in docs/node_api.md nor in its device's README.md";
  }
  for (const std::string& key : documented) {
    EXPECT_TRUE(in_table.count(key) || kDocumentedOutsideTheTable.count(key))
        << "the docs document ~" << key << ", which the parameter table does not have";
  }
}

TEST(ParameterDocs, NodeApiDefaultsAreTheTableDefaults) {
  const DriverParams defaults;
  int compared = 0;
  for (const DocumentedParam& param : documentedParams()) {
    if (kDocumentedOutsideTheTable.count(param.key) || param.default_text.empty()) continue;
    SCOPED_TRACE(param.file + ":" + std::to_string(param.line) + " ~" + param.key);
    ASSERT_NO_THROW(specFor(param.key));
    const ParamValue table_default = specFor(param.key).get(defaults);
    EXPECT_TRUE(statesDefault(param.default_text, table_default))
        << "the doc says " << param.default_text << ", the table " << toText(table_default);
    ++compared;
  }
  EXPECT_GT(compared, 50) << "the doc's default column was not read";
}

TEST(ParameterDocs, TheDefaultsReaderReadsEachType) {
  EXPECT_TRUE(statesDefault("0.0047884", 16 * 9.80665 / 32768));
  EXPECT_FALSE(statesDefault("0.0047", 16 * 9.80665 / 32768));
  EXPECT_TRUE(statesDefault("50", 50.0));
  EXPECT_FALSE(statesDefault("50 Hz", 50.0));
  EXPECT_TRUE(statesDefault("\"\"", std::string()));
  EXPECT_TRUE(statesDefault("odom", std::string("odom")));
  EXPECT_TRUE(statesDefault("[1, 2]", std::vector<int>{1, 2}));
  EXPECT_FALSE(statesDefault("[1, 2]", std::vector<int>{1}));
  EXPECT_TRUE(statesDefault("[]", std::vector<double>{}));
  EXPECT_TRUE(statesDefault("[x, y, z]", std::vector<std::string>{"x", "y", "z"}));
  EXPECT_FALSE(statesDefault("1", true));
}

/// Every leaf key of `node` as "a/b/c"; a list is a value, not a map.
void collectKeys(const YAML::Node& node, const std::string& prefix,
                 std::vector<std::string>& keys) {
  for (const auto& entry : node) {
    const std::string key = prefix + entry.first.as<std::string>();
    if (entry.second.IsMap()) {
      collectKeys(entry.second, key + "/", keys);
    } else {
      keys.push_back(key);
    }
  }
}

TEST(ParameterDocs, RobotYamlUsesOnlyKeysOfTheTable) {
  const YAML::Node config = YAML::LoadFile(kSourceDir + "/config/robot.yaml");
  std::vector<std::string> keys;
  collectKeys(config, "", keys);
  EXPECT_GT(keys.size(), 50u);
  std::set<std::string> in_table;
  for (const ParamSpec& spec : parameterTable()) in_table.insert(spec.key);
  for (const std::string& key : keys) {
    EXPECT_TRUE(in_table.count(key))
        << "config/robot.yaml sets ~" << key << ", which the parameter table does not have";
  }
}

}  // namespace
}  // namespace serial_robot_driver::params
