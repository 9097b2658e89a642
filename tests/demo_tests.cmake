# The main job as a test: scripts/test.sh builds, then ctest runs scripts/demo.sh (already built: BLURCUE_BUILT=1)
# beside the other tests rather than before them - the demo is one process at a time, so on two cores it shares the
# machine with the tests instead of leaving a core idle for its 4 minutes. It runs this build's blurcue and writes into
# BUILD/results (demo, bench, protocols pointed at it), which no other test reads or writes: two builds of one source
# tree test at once without meeting.
add_test(NAME demo COMMAND bash ${PROJECT_SOURCE_DIR}/scripts/demo.sh WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
set_tests_properties(demo PROPERTIES
                     ENVIRONMENT "BLURCUE_BUILT=1;BLURCUE_BIN=$<TARGET_FILE:blurcue>;BLURCUE_RESULTS=${PROJECT_BINARY_DIR}/results"
                     TIMEOUT 1500 LABELS "slow;demo"
                     FIXTURES_SETUP demo_outputs)
# The demo's benchmarks on their values (tests/bench_check.py): the edge model within its targets and better than the
# thesis's measure, the GL blur within a grey level of the CPU reference.
add_test(NAME demo_bench_values
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/bench_check.py ${PROJECT_BINARY_DIR}/results/bench)
set_tests_properties(demo_bench_values PROPERTIES FIXTURES_REQUIRED demo_outputs LABELS demo)
set_test_costs(demo 400)
