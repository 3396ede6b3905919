// The Catch2 (v2) main of gauss6_reference_tests.
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
