// The URDF text of the robot description, written element by element (ROS-free): the document
// with its materials, links and joints (each name once), and the simple shapes the devices draw.
#pragma once

#include <initializer_list>
#include <set>
#include <sstream>
#include <string>

namespace serial_robot_driver::description {

/// `values` separated by spaces, 9 significant digits, no "-0".
std::string numbers(std::initializer_list<double> values);

/// A wheel's or servo's link: the joint name without a trailing "_joint", plus "_link".
std::string childLink(const std::string& joint);

/// One <visual> of `geometry` (box(), cylinder(), sphere()) in `material`, at `xyz` / `rpy`.
std::string visual(const std::string& geometry, const std::string& material,
                   const std::string& xyz = "0 0 0", const std::string& rpy = "0 0 0");
std::string box(double x, double y, double z);
std::string cylinder(double radius, double length);
std::string sphere(double radius);

class UrdfWriter {
 public:
  /// Starts the document of robot `robot_name` with the materials the devices draw in.
  explicit UrdfWriter(const std::string& robot_name);

  /// A link named by parameter `key` (for errors); throws ParameterError when `name` is taken.
  void link(const std::string& name, const std::string& key, const std::string& visuals);
  /// A joint named by parameter `key` (for errors); throws ParameterError when `name` is taken.
  /// `extra`: its further elements (axis, limit), each line indented and ended.
  void joint(const std::string& name, const std::string& key, const std::string& type,
             const std::string& parent, const std::string& child, const std::string& xyz,
             const std::string& rpy, const std::string& extra);

  /// The document, closed.
  std::string finish();

 private:
  std::ostringstream out_;
  std::set<std::string> links_, joints_;
};

}  // namespace serial_robot_driver::description
