# cmake -DTEST_EXECUTABLE=<nlosloc_tests> -P nloslocCheckTestNames.cmake
# Fails when a Catch2 test-case name contains '[' or ']' (or ';'): catch_discover_tests (Catch2 2.13) splits
# the name list as a CMake list, and such a name silently merges with its neighbours into one ctest entry
# that runs neither. Put tags in the second TEST_CASE argument, and write intervals as "(-pi, pi)".
execute_process(COMMAND "${TEST_EXECUTABLE}" --list-test-names-only OUTPUT_VARIABLE out
                RESULT_VARIABLE rc)
if(rc LESS 0)
  message(FATAL_ERROR "could not list the tests of ${TEST_EXECUTABLE}")
endif()
string(REGEX MATCHALL "[^\n]*[][;][^\n]*" bad "${out}")
if(bad)
  message(FATAL_ERROR "Catch2 test names must not contain '[', ']' or ';' (catch_discover_tests mangles "
                      "them):\n  ${bad}")
endif()
message(STATUS "test names ok")
