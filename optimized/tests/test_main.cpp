// Catch2 entry point of the optimized/ test suite (one main for all test files).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
