# blurcue synth-take and blurcue track end to end (tests/track_test.sh); the tracker against a ground-truth take is
# src/track/tracker_test.cc.
add_test(NAME track_cli COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/track_test.sh $<TARGET_FILE:blurcue>
                                ${PROJECT_BINARY_DIR}/track-test)

# The track bench on 4 frames writes one row per (mode, frame) - track, track-serial, detect, calibrate in process and
# calibrate run as a command - and says the targets and the measured ratio in words; its chart is drawn.
add_test(NAME cli_bench_track_quick
         COMMAND ${BLURCUE_EXPECT} "wrote .*track.csv \\(20 rows\\).*track +4 .*\\(3 tracked\\).*calibrate-process +4 .*track: median [0-9.]+ ms a frame wall.*track vs calibrate run as a command on each frame: [0-9.]+x faster" $<TARGET_FILE:blurcue> bench track --quick --out ${PROJECT_BINARY_DIR}/track-bench/track.csv)
set_tests_properties(cli_bench_track_quick PROPERTIES LABELS slow FIXTURES_SETUP track_bench)
add_test(NAME cli_bench_track_chart
         COMMAND ${BLURCUE_EXPECT} "wrote .*bench-track.png" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/analysis/track_chart.py
                 ${PROJECT_BINARY_DIR}/track-bench/track.csv ${PROJECT_BINARY_DIR}/track-bench)
set_tests_properties(cli_bench_track_chart PROPERTIES FIXTURES_REQUIRED track_bench LABELS slow
                     WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}/analysis)
# blurcue ar on a ground-truth take: the ball's place and defocus against the truth, the card's blur and streak measured
# on the written frames by numpy (tests/ar_check.py), a truncated input, bad names and values (tests/ar_test.sh).
add_test(NAME ar_cli COMMAND ${BLURCUE_EXPECT} "(^|\n)ok: ar_test" bash ${PROJECT_SOURCE_DIR}/tests/ar_test.sh $<TARGET_FILE:blurcue>
                             ${PROJECT_BINARY_DIR}/ar-test)
set_tests_properties(ar_cli PROPERTIES LABELS gl)
set_tests_properties(ar_cli PROPERTIES FIXTURES_SETUP ar_take)
# The ball's r against the take's TRUE lens within 3 % (issue 27's target): the take's fitted lens model, which
# `ar --blur fitted` draws with, must be the true one.
add_test(NAME ar_defocus_truth_lens
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/ar_check.py ${PROJECT_BINARY_DIR}/ar-test --truth-lens)
set_tests_properties(ar_defocus_truth_lens PROPERTIES FIXTURES_REQUIRED ar_take)
# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(ar_cli 56)
