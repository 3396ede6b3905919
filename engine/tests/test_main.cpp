// Catch2 entry point of the engine/ test suite (one main for all its test files).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
