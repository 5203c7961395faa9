// The source of srd_ros_test_pch (cmake/precompiled_headers.cmake): the target exists only to
// build the precompiled header that the roscpp gtests reuse; it compiles nothing of its own.
