// The main() of every Catch2 test executable (object library nlosloc_catch_main); the test cases live in
// tests/cpp/test_*.cpp and tests/nomalloc.
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
