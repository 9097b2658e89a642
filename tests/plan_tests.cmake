# blurcue plan end to end over the CLI tests' scene (fixtures scene, calib, session_protocols): tests/plan_test.sh.
set(BC $<TARGET_FILE:blurcue>)
set(T ${PROJECT_BINARY_DIR}/cli-test)
foreach(case same_as_run power_exact same_seed chart prediction depth_slope threshold_truth difference_power groups
       difference_meaningless units_and_groups groups_shared_block design_warnings more_blurred_as_report)
  add_test(NAME plan_${case} COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/plan_test.sh ${case} ${BC} ${T})
  set_tests_properties(plan_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols;session_pictures" LABELS "gl;plan" TIMEOUT 600)
endforeach()
set_tests_properties(plan_chart PROPERTIES ENVIRONMENT "MPLCONFIGDIR=${PROJECT_BINARY_DIR}/mplconfig")

# Bad input: exit code and one line naming the option or file (tests/expect_failure.cmake). NAME CODE TEXT ARGS...
function(add_plan_failure_test name code text)
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=${ARGN}" -DEXPECT_CODE=${code} "-DEXPECT_TEXT=${text}"
                   -DONE_LINE=1 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
  set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS plan)
endfunction()
set(P1 ${T}/protocols/test1-static-grids.json)
add_plan_failure_test(plan_bad_n_zero 2 "--participants: must be a whole number in [1, 10000], got 0"
                      plan ${P1} --participants 0 --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_bad_n_negative 2 "--participants: must be a whole number in [1, 10000], got -1"
                      plan ${P1} --participants=-1 --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_bad_n_huge 2 "--participants: must be a whole number in [1, 10000], got '1e308'"
                      plan ${P1} --participants 1e308 --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_bad_n_nan 2 "--participants: must be a whole number in [1, 10000], got 'nan'"
                      plan ${P1} --participants nan --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_bad_studies 2 "--studies: must be a whole number in [1, 100000], got 0"
                      plan ${P1} --studies 0 --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_bad_alpha 2 "--alpha: must be a number in (0, 0.5], got 'nan'"
                      plan ${P1} --alpha nan --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_bad_observer 2 "--observer: unknown parameter 'jdn'"
                      plan ${P1} --observer sim:jdn=1 --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_missing_protocol 3 "no-such-protocol.json: cannot open file"
                      plan ${T}/no-such-protocol.json --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_protocol_is_a_folder 3 "protocols: is a folder, not a JSON file"
                      plan ${T}/protocols --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_display_is_a_folder 3 "protocols: is a folder"
                      plan ${P1} --display ${T}/protocols --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_missing_display 3 "no-such-display.json: cannot open file"
                      plan ${P1} --display ${T}/no-such-display.json --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_out_is_a_file 3 "test1-static-grids.json: --out: is a file, not a folder"
                      plan ${P1} --no-chart --out ${P1})
add_plan_failure_test(plan_too_many 2 "--participants x --studies must be at most 20000000"
                      plan ${P1} --participants 10000 --studies 100000 --no-chart --out ${T}/plan-bad)
add_plan_failure_test(plan_bad_python 2 "--python /no/such/python: not found"
                      plan ${P1} --participants 2 --studies 1 --python /no/such/python --out ${T}/plan-bad)
# A --python that starts but is no Python 3 is refused before the simulation (it ended in exit 10, "its message is
# above" with nothing above, or in exit 0 with no chart), and so is an --out holding files of something else.
foreach(fake true false)
  add_plan_failure_test(plan_python_${fake} 2 "--python /bin/${fake}: not a Python 3"
                        plan ${P1} --participants 2 --studies 1 --python /bin/${fake} --out ${T}/plan-bad)
endforeach()
add_test(NAME report_python_false
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=report;--db;${P1};--python;/bin/false;--out;${T}/report-bad"
                 -DEXPECT_CODE=2 "-DEXPECT_TEXT=--python /bin/false: not a Python 3" -DONE_LINE=1
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(report_python_false PROPERTIES FIXTURES_REQUIRED session_protocols LABELS plan)
add_plan_failure_test(plan_out_holds_other_files 3 "protocols: holds "
                      plan ${P1} --participants 2 --studies 1 --no-chart --out ${T}/protocols)

# Numbers as typed: a leading zero is decimal (CLI11 alone reads 010 as octal 8), a seed as export writes it
# (s<digits>) is that seed - both options rewrite their text, which CLI11 keeps only from a transform, not a check.
add_test(NAME plan_leading_zero_is_decimal
         COMMAND ${BLURCUE_EXPECT} "1 simulated studies of 10 participants \\(seed 5\\)" ${BC} plan ${P1} --participants 010 --studies 1 --seed s5 --no-chart --out ${T}/plan-leading-zero)
set_tests_properties(plan_leading_zero_is_decimal PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                     LABELS plan)
# The exact binomial test's p of every k of every n up to the trials of 10000 participants: one O(n) sum per k made it
# O(n^3) (3 minutes after a 4 s simulation at 3000 x 20; past 60 s, unfinished, at --participants 10000). Now
# O(n log n) per n: seconds (a timeout is no speed test: bench plan times it; this one checks that it finishes).
add_test(NAME plan_ten_thousand_participants
         COMMAND ${BLURCUE_EXPECT} "1 simulated studies of 10000 participants" ${BC} plan ${P1} --participants 10000 --studies 1 --no-chart --out ${T}/plan-many)
set_tests_properties(plan_ten_thousand_participants PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                     LABELS plan TIMEOUT 600)
add_plan_failure_test(plan_bad_difference 2 "--difference: must be a non-zero number in the procedure's units (0.5) or a percentage of the true threshold (20%), got 'abc'"
                      plan ${T}/protocols/quest-blur-difference.json --difference abc --no-chart --out ${T}/plan-bad)
# A long --difference is quoted as every typed value is: its first 60 characters and its length (it was echoed whole).
string(REPEAT x 200 LONG_DIFFERENCE)
add_plan_failure_test(plan_bad_difference_long 2 "got 'xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx...' (200 characters)"
                      plan ${T}/protocols/quest-blur-difference.json --difference ${LONG_DIFFERENCE} --no-chart --out ${T}/plan-bad)
add_test(NAME plan_difference_without_procedure
         COMMAND ${BLURCUE_EXPECT} "note: --difference is not planned: it is a difference between thresholds" ${BC} plan ${P1} --participants 2 --studies 1 --difference 0.5 --no-chart --out ${T}/plan-no-procedure)
set_tests_properties(plan_difference_without_procedure PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                     LABELS plan)
add_plan_failure_test(plan_zero_difference 2 "--difference: must be a non-zero number"
                      plan ${T}/protocols/quest-blur-difference.json --difference 0% --no-chart --out ${T}/plan-bad)

# bench plan times the adaptive protocol by its name beside --protocol's: the same study twice had its runs merged
# into one median, a protocol without a procedure passed as the adaptive one; both are usage errors now.
add_plan_failure_test(bench_plan_adaptive_is_protocol 2
                      "--adaptive-protocol ${P1}: the same study as --protocol (test1-static-grids); 'none' times --protocol alone"
                      bench plan --quick --participants 2 --protocol ${P1} --adaptive-protocol ${P1} --out ${T}/bench-plan-bad.csv)
add_plan_failure_test(bench_plan_adaptive_without_procedure 2
                      "--adaptive-protocol ${T}/protocols/groups-and-info.json: no block has a procedure (staircase or QUEST+), got study groups-and-info"
                      bench plan --quick --participants 2 --protocol ${P1} --adaptive-protocol ${T}/protocols/groups-and-info.json --out ${T}/bench-plan-bad.csv)

# Every group checked: validate, validate --plan and preview cover each group of a protocol with groups (groups-and-info:
# 6 edges x 2 swapped copies = 12 trials in each group's own block), or only --group's; an unknown group is a usage
# error with the nearest name.
set(G ${T}/protocols/groups-and-info.json)
add_test(NAME validate_every_group COMMAND ${BLURCUE_EXPECT} "ok: 12 trials [^\n]*, group estimated\n  measured-vs-estimated 12 [^\n]*\n.*ok: 12 trials [^\n]*, group no_blur\n  measured-vs-none 12 " ${BC} validate ${G})
set_tests_properties(validate_every_group PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS plan)
add_test(NAME validate_plan_every_group COMMAND ${BLURCUE_EXPECT} "group: estimated [^\n]*\n.*visibility [^\n]*6 distinct pairs.*group: no_blur [^\n]*\n.*visibility [^\n]*6 distinct pairs" ${BC} validate ${G} --plan)
set_tests_properties(validate_plan_every_group PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS plan)
add_test(NAME validate_one_group COMMAND ${BLURCUE_EXPECT} "ok: 12 trials [^\n]*, group no_blur\n  measured-vs-none 12 " ${BC} validate ${G} --group no_blur)
set_tests_properties(validate_one_group PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS plan FAIL_REGULAR_EXPRESSION "group estimated")
add_test(NAME validate_every_group_no_files COMMAND ${BLURCUE_EXPECT} "group estimated\n  measured-vs-estimated 12 [^\n]*\nok: 12 trials [^\n]*, group no_blur\n  measured-vs-none 12 " ${BC} validate ${PROJECT_SOURCE_DIR}/protocols/groups-and-info.json --no-files)
set_tests_properties(validate_every_group_no_files PROPERTIES LABELS plan)
add_plan_failure_test(validate_unknown_group 2
                      "--group no_blr: ${G} has no such group (did you mean no_blur? its groups: estimated, no_blur)"
                      validate ${G} --group no_blr)
add_plan_failure_test(validate_group_without_groups 2 "--group estimated: ${P1} has no groups"
                      validate ${P1} --group estimated)
# --group as typed is echoed as every value is: a long one cut at 60 characters with its length, one with a space at either end quoted.
string(REPEAT x 5000 LONG_GROUP)
add_plan_failure_test(validate_group_long 2 "--group xxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxxx... (5000 characters): ${G} has no such group"
                      validate ${G} --group ${LONG_GROUP})
add_plan_failure_test(validate_group_blank 2 "--group ' no_blur': ${G} has no such group (did you mean no_blur?" validate ${G} --group " no_blur")
add_test(NAME preview_every_group COMMAND ${BLURCUE_EXPECT} "#1 group estimated: edge 1: .*#13 group no_blur: edge 1: .*24 distinct stimuli of 24 trials \\(groups estimated, no_blur\\)" ${BC} preview ${G} --list --out ${T}/preview-groups.png)
set_tests_properties(preview_every_group PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS "gl;plan")
# The preview shows every object at 1:1 screen scale: each inset equals the frame run --capture wrote for the same
# trial, pixel for pixel, around the object's outline; labels stay inside their tile.
add_test(NAME preview_insets_1to1
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/preview_inset_check.py ${BC} ${P1} ${T}/preview-insets)
set_tests_properties(preview_insets_1to1 PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS "gl;plan")
# ... and says what the slowest tile cost against the display's frame (16.7 ms at the default profile's 60 Hz): a
# per-pixel tile took 120-200 ms on llvmpipe, where ms/frame alone on a tile did not say whether that is too slow.
add_test(NAME preview_one_group COMMAND ${BLURCUE_EXPECT} "12 distinct stimuli of 12 trials \\(groups no_blur\\).*\nnote: (every tile composed within the display's frame here \\(the slowest, #[0-9]+, [0-9.]+ ms of 16.7 ms at 60 Hz\\)|[0-9]+ of 12 tiles took longer to compose here than the display's frame \\(16.7 ms at 60 Hz; the slowest)" ${BC} preview ${G} --group no_blur --list --out ${T}/preview-group.png)
set_tests_properties(preview_one_group PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS "gl;plan" FAIL_REGULAR_EXPRESSION "group estimated")
add_plan_failure_test(preview_unknown_group 2 "--group estimatd: ${G} has no such group (did you mean estimated?"
                      preview ${G} --group estimatd --out ${T}/preview-bad.png)

# The chart's own tests (analysis/tests/test_plan_chart.py), with the analysis's Python (tests/analysis_tests.cmake,
# included after this file, declares the same cache entry).
set(BLURCUE_ANALYSIS_PYTHON /usr/bin/python3 CACHE FILEPATH "Python with pandas, scipy, matplotlib, statsmodels")
add_test(NAME analysis.plan_chart
         COMMAND ${BLURCUE_ANALYSIS_PYTHON} -m unittest discover -s analysis/tests -t analysis -p test_plan_chart.py
         WORKING_DIRECTORY ${CMAKE_SOURCE_DIR})
set_tests_properties(analysis.plan_chart PROPERTIES LABELS "analysis;plan" TIMEOUT 180
                     ENVIRONMENT "MPLCONFIGDIR=${PROJECT_BINARY_DIR}/mplconfig;PYTHONDONTWRITEBYTECODE=1")
# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(plan_same_as_run 34 plan_difference_power 32 plan_more_blurred_as_report 23)
# A single object against the scene's blur (yes-no-ball): below the level it looks as blurred as the scene - what
# such a study asks - said so, not flagged "invisible" as a pair no one could tell apart (a newcomer read the red
# INVISIBLE on the measured condition as a defect).
add_test(NAME validate_plan_single_objects COMMAND ${BLURCUE_EXPECT} "0 distinct pairs, 0 invisible; 9 single objects, [1-9] as blurred as the scene to this observer\n.*object measured vs the scene [^\n]* - as blurred as the scene at 60 cm on this monitor" ${BC} validate ${T}/protocols/yes-no-ball.json --plan)
set_tests_properties(validate_plan_single_objects PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS plan
  FAIL_REGULAR_EXPRESSION "invisible at")

# Issue 38's must-hold: the report's per-track thresholds against 30 simulated observers of drawn Weber fraction,
# their truth worked out from docs/observer.md in tests/threshold_coverage_check.py - the shipped staircase, a
# 1-up/3-down variant of it (48 trials, no stop rule) and the shipped QUEST+ protocol.
add_test(NAME threshold_coverage_staircase
         COMMAND bash ${PROJECT_SOURCE_DIR}/tests/threshold_coverage_test.sh ${BC} ${T}/protocols/staircase-ball-gain.json
                 staircase ${T}/coverage-staircase 30)
add_test(NAME threshold_coverage_1up3down
         COMMAND bash ${PROJECT_SOURCE_DIR}/tests/threshold_coverage_test.sh ${BC} ${T}/protocols/staircase-ball-gain.json
                 staircase ${T}/coverage-1up3down 30
                 "p['name'] += '-1up3down'; pr = p['blocks'][0]['procedure']; pr.update(down=3, trials=48); pr.pop('stop')")
add_test(NAME threshold_coverage_quest
         COMMAND bash ${PROJECT_SOURCE_DIR}/tests/threshold_coverage_test.sh ${BC} ${T}/protocols/quest-blur-difference.json
                 quest_plus ${T}/coverage-quest 30)
set_tests_properties(threshold_coverage_staircase threshold_coverage_1up3down threshold_coverage_quest PROPERTIES
                     FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS "gl;plan" TIMEOUT 600)
set_tests_properties(threshold_coverage_staircase threshold_coverage_1up3down PROPERTIES ENVIRONMENT "FPS=0.2")
set_test_costs(threshold_coverage_1up3down 71 threshold_coverage_staircase 42 threshold_coverage_quest 39)
# validate's blur plan for a procedure's trials bounds what run records (tests/blur_plan_bounds.py): a staircase of
# grid cards at a near and a far edge (validate said 0 of 80 per pixel; run drew 138 of 226 so).
file(WRITE ${T}/plan-stairs.json [=[
{"name": "plan-stairs", "version": 1,
 "scene": {"background": "scene/scene.png", "calib": "calib.json"},
 "content": {"type": "grid", "cells": 5}, "task": "forced_choice",
 "blocks": [{"name": "stairs", "factors": {"edge": [4, 9]},
   "procedure": {"type": "staircase", "variable": "relative_difference", "reference": "measured", "trials": 40,
                 "start": 1.0, "min": 0.02, "max": 3, "up": 1, "down": 2, "steps": [0.4, 0.2, 0.1],
                 "stop": {"reversals": 8}}}],
 "responses": {"left": "Left", "right": "Right"}}
]=])
add_test(NAME validate_blur_plan_bounds_the_record
         COMMAND ${BLURCUE_EXPECT} "ok: the record keeps within validate's blur plan" /usr/bin/python3
                 ${PROJECT_SOURCE_DIR}/tests/blur_plan_bounds.py ${BC} ${T}/plan-stairs.json ${T}/plan-stairs.sqlite)
set_tests_properties(validate_blur_plan_bounds_the_record PROPERTIES FIXTURES_REQUIRED "scene;calib" LABELS plan)
# Ctrl-C during run (tests/run_interrupt.py): stops between trials, says what was saved, exits 130; --resume completes.
add_test(NAME run_interrupted_says_what_was_saved
         COMMAND ${BLURCUE_EXPECT} "ok: Ctrl-C stops run with every answer saved" /usr/bin/python3
                 ${PROJECT_SOURCE_DIR}/tests/run_interrupt.py ${BC} ${T}/plan-stairs.json ${T}/run-interrupted.sqlite)
set_tests_properties(run_interrupted_says_what_was_saved PROPERTIES FIXTURES_REQUIRED "scene;calib" LABELS session)
# `measured` at an edge with no usable section (the CLI scene's edge 1: its seven readings phase_limited, pooled into
# the lens fit) was drawn with no word; validate and render now say what that value is, as for fitted blur where the
# model is not determined. Edge 4 (seven usable sections) gets none.
file(WRITE ${T}/pooled-edges.json [=[
{"name": "pooled-edges", "version": 1,
 "scene": {"background": "scene/scene.png", "calib": "calib.json"},
 "content": {"type": "grid", "cells": 5}, "task": "forced_choice",
 "sides": {"left": "measured", "right": "none"},
 "blocks": [{"name": "main", "factors": {"edge": [1, 4]}}],
 "responses": {"left": "Left", "right": "Right"}}
]=])
add_test(NAME validate_measured_pooled_edge_note
         COMMAND ${BLURCUE_EXPECT} "\n  note: 1 of 2 trials show the measured blur of an edge with no usable section; the first: the measured blur at edge 1 \\([0-9.]+ px\\) is the mean of 7 readings none of which is usable alone"
                 ${BC} validate ${T}/pooled-edges.json)
add_test(NAME render_measured_pooled_edge_note
         COMMAND ${BLURCUE_EXPECT} "\nnote: the measured blur at edge 1 \\([0-9.]+ px\\) is the mean of 7 readings none of which is usable alone"
                 ${BC} render --calib ${T}/calib.json --background ${T}/scene/scene.png --object ball --at-edge 1
                 --blur measured --out ${T}/pooled-edge-ball.png)
add_test(NAME render_measured_usable_edge_no_note
         COMMAND ${BLURCUE_EXPECT} "^ball at edge 4: [^\n]*\n$"
                 ${BC} render --calib ${T}/calib.json --background ${T}/scene/scene.png --object ball --at-edge 4
                 --blur measured --out ${T}/usable-edge-ball.png)
set_tests_properties(validate_measured_pooled_edge_note render_measured_pooled_edge_note
                     render_measured_usable_edge_no_note PROPERTIES FIXTURES_REQUIRED "scene;calib" LABELS "plan;gl")
