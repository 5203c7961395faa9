# Sourced by .ci/run: one ccache for the package's two builds, scripts/build.sh's (.ws/) and the
# catkin_tools check's (scripts/test_catkin_build.sh), so that the second compiles almost nothing
# of its own. ccache hashes a compile's paths relative to CCACHE_BASEDIR (the repository) and its
# working folder, so the check builds with its source and build spaces beside build.sh's, at the
# same depth (.ws/catkin_tools_src/, .ws/catkin_tools_build/), while its devel and install spaces
# stay outside the repository (see test_catkin_build.sh). The two devel spaces' include folders
# are left out of the hash: the headers generated there are the same in both builds, and ccache
# still checks the content of every header a compile read.
# Needs scratch_dir (scripts/scratch_dir.sh) and repo, ws (the repository and its .ws/).
shared_ccache() {
  command -v ccache >/dev/null || return 0
  local catkin_tools_ws
  catkin_tools_ws="${SRD_CATKIN_TOOLS_WS:-$(scratch_dir "$repo" catkin_tools)}"
  export CCACHE_DIR="$ws/ccache" CCACHE_BASEDIR="$repo" CCACHE_NOHASHDIR=1 CCACHE_DEPEND=1
  # The form the option takes in the hash (relative to the build folder) and as given.
  export CCACHE_IGNOREOPTIONS="-I../../devel/include -I$ws/devel/include -I$catkin_tools_ws/devel*"
  export SRD_CATKIN_TOOLS_SPACES_IN="$ws"
  ci_cmake_args+=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DSRD_PRECOMPILED_HEADERS=ON)
}
