# Sourced by the scripts that build the package a second time (test_catkin_build.sh, tsan.sh):
# scratch_dir REPO NAME prints (and creates) a folder for that build outside the repository,
# one per clone. Outside, because rosrun looks for an executable anywhere below the package's
# folder (the repository): a second build tree there makes `rosrun serial_robot_driver <tool>`
# ask which of its copies to run.
scratch_dir() {
  local key
  key=$(printf '%s' "$1" | md5sum | cut -c1-8)
  local dir="${XDG_CACHE_HOME:-$HOME/.cache}/serial_robot_driver/$(basename "$1")-$key/$2"
  mkdir -p "$dir"
  printf '%s\n' "$dir"
}
