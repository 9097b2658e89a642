# The warnings every target of ours compiles with. -Wno-array-bounds: a GCC 12 false positive in nlohmann/json;
# -Wno-restrict: GCC 12 flags std::string assignments and "literal" + std::to_string(...) inside libstdc++ (GCC bug
# 105651), not code of ours. -Wswitch-enum: a switch over an enum lists every value even with a default:, so a new
# value (a protocol's layout, task...) shows every place to touch.
set(BLURCUE_WARNINGS -Wall -Wextra -Wswitch-enum -Wno-array-bounds -Wno-restrict)

# add_module_library(NAME SRCS a.cc b.cc DEPS other libs)
#   One static library per module folder, headers beside sources, included as "module/foo.h".
function(add_module_library name)
  cmake_parse_arguments(ARG "" "" "SRCS;DEPS" ${ARGN})
  add_library(blurcue_${name} STATIC ${ARG_SRCS})
  target_include_directories(blurcue_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(blurcue_${name} PUBLIC ${ARG_DEPS})
  target_compile_options(blurcue_${name} PRIVATE ${BLURCUE_WARNINGS})
  # Four sources to a translation unit (a unity build: OpenCV and json parsed once per four), ~1 of 6 minutes of a
  # cold build on two cores; names in a source's anonymous namespace must therefore be its own within the module.
  set_target_properties(blurcue_${name} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 4)
endfunction()

# add_module_test(NAME SRCS a_test.cc DEPS libs [LABELS gl slow] [ONE_PROCESS] [ONE_AT_A_TIME])
#   One GoogleTest executable, registered with CTest test by test; with ONE_PROCESS as one CTest test (for tests that
#   share an expensive set-up made once per process, such as a rendered take: CTest runs each test in a process).
#   ONE_AT_A_TIME: its tests never run at the same time as each other under ctest -j (RESOURCE_LOCK), for tests that
#   write the same files in one fixed temporary folder.
function(add_module_test name)
  cmake_parse_arguments(ARG "ONE_PROCESS;ONE_AT_A_TIME" "" "SRCS;DEPS;LABELS" ${ARGN})
  add_executable(${name} ${ARG_SRCS})
  target_link_libraries(${name} PRIVATE ${ARG_DEPS} GTest::gtest_main)
  target_compile_options(${name} PRIVATE ${BLURCUE_WARNINGS})
  # The test's own code at -O1 (its gtest macros cost 40 % less to compile than at -O3); the code under test runs as
  # built, from the module libraries.
  if(CMAKE_BUILD_TYPE STREQUAL "Release")
    target_compile_options(${name} PRIVATE -O1)
  endif()
  # A module's test files compiled four to a translation unit (a unity build): gtest, nlohmann/json and OpenCV are
  # parsed once per four files instead of once per file (protocol_test's seven files: 31 s of CPU instead of 86 s).
  # Helpers in a test file's anonymous namespace therefore have names of their own across the module's tests.
  set_target_properties(${name} PROPERTIES UNITY_BUILD ON UNITY_BUILD_BATCH_SIZE 4)
  if(ARG_ONE_PROCESS)
    add_test(NAME ${name} COMMAND ${name} WORKING_DIRECTORY ${PROJECT_BINARY_DIR})
    set_tests_properties(${name} PROPERTIES LABELS "${ARG_LABELS}" COST 100)  # long: started first (COST: set_test_costs)
    return()
  endif()
  set(lock)
  if(ARG_ONE_AT_A_TIME)
    set(lock RESOURCE_LOCK ${name})
  endif()
  include(GoogleTest)
  gtest_discover_tests(${name} WORKING_DIRECTORY ${PROJECT_BINARY_DIR} NO_PRETTY_VALUES
                       PROPERTIES LABELS "${ARG_LABELS}" ${lock} DISCOVERY_TIMEOUT 60)
endfunction()

# set_test_costs(NAME SECONDS [NAME SECONDS ...])
#   A long test's COST: its seconds in one ctest -j2 run. CTest starts the costliest ready tests first until it has
#   timed the tests itself (build/Testing/Temporary/CTestCostData.txt, absent on a fresh clone, as in CI): a test of
#   minutes started last would run alone at the end. Called where the tests are added (set_tests_properties sees only
#   the tests of its own directory).
function(set_test_costs)
  set(args ${ARGN})
  while(args)
    list(POP_FRONT args name seconds)
    set_tests_properties(${name} PROPERTIES COST ${seconds})
  endwhile()
endfunction()

# ${BLURCUE_EXPECT} "REGEX" COMMAND...: a test's command that passes only with exit 0 and output matching REGEX
# (tests/expect_output.py). Used in place of CTest's PASS_REGULAR_EXPRESSION, which ignores the exit code; the test
# suite_checks_exit_codes refuses a test that sets it.
set(BLURCUE_EXPECT /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/expect_output.py)
