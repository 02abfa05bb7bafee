# pl_add_module(NAME SOURCES ... DEPS ... [PRIVATE_DEPS ...])
#   A static library pl_<NAME> with include root src/ (so headers are "module/header.h").
# pl_add_test(NAME SOURCES ... DEPS ...)
#   A GoogleTest executable <NAME> registered with ctest (tests discovered one by one).
function(pl_add_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(pl_${name} STATIC ${ARG_SOURCES})
  target_include_directories(pl_${name} PUBLIC ${CMAKE_SOURCE_DIR}/src)
  target_link_libraries(pl_${name} PUBLIC ${ARG_DEPS} PRIVATE pl_warnings ${ARG_PRIVATE_DEPS})
  # -fPIC: the modules are also linked into the Python extension (a shared object).
  set_target_properties(pl_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
endfunction()

function(pl_add_test name)
  if(NOT BUILD_TESTING)
    return()
  endif()
  cmake_parse_arguments(ARG "" "" "SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${ARG_SOURCES})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} pl_warnings GTest::gtest GTest::gtest_main)
  # tests/support: helpers shared by test files (e.g. support/cli_test_support.h).
  target_include_directories(${name} PRIVATE ${CMAKE_SOURCE_DIR}/tests)
  target_compile_definitions(${name} PRIVATE
    PLENOPTIC_TEST_DATA_DIR="${PLENOPTIC_TEST_DATA_DIR}"
    PLENOPTIC_BINARY="$<TARGET_FILE:plenoptic>")
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
    PROPERTIES ENVIRONMENT "SDL_VIDEODRIVER=dummy")
endfunction()
