# blurcue live (issue 43) on a 60-frame ground-truth take (tests/live_test.sh, checked by tests/live_check.py): played
# at 30 fps through a window under Xvfb and headless, every pose against the truth and the ball against ar's; a
# missing camera. The GL-free parts (mailbox, plan, log) are src/live/live_test.cc.
set(LIVE_TEST bash ${PROJECT_SOURCE_DIR}/tests/live_test.sh)
set(LIVE_DIR ${PROJECT_BINARY_DIR}/live-test)
add_test(NAME live_make COMMAND ${BLURCUE_EXPECT} "ok: live_test make" ${LIVE_TEST} make $<TARGET_FILE:blurcue> ${LIVE_DIR})
set_tests_properties(live_make PROPERTIES FIXTURES_SETUP live_take LABELS gl)
add_test(NAME live_headless_video_ends
         COMMAND ${BLURCUE_EXPECT} "ok: live_test headless" ${LIVE_TEST} headless $<TARGET_FILE:blurcue> ${LIVE_DIR})
set_tests_properties(live_headless_video_ends PROPERTIES FIXTURES_REQUIRED live_take LABELS gl)
add_test(NAME live_missing_camera
         COMMAND ${BLURCUE_EXPECT} "ok: live_test nocamera" ${LIVE_TEST} nocamera $<TARGET_FILE:blurcue> ${LIVE_DIR})
set_tests_properties(live_missing_camera PROPERTIES FIXTURES_REQUIRED live_take)
# Refused before the first frame: a --log live may not replace (exit 2 for what it holds, 3 for a file), and a
# --preload of more than 2000 MB, counted before a frame is decoded (tests/live_test.sh refusals).
add_test(NAME live_refusals
         COMMAND ${BLURCUE_EXPECT} "ok: live_test refusals" ${LIVE_TEST} refusals $<TARGET_FILE:blurcue> ${LIVE_DIR})
set_tests_properties(live_refusals PROPERTIES FIXTURES_REQUIRED live_take)
find_program(LIVE_XVFB Xvfb)
find_program(LIVE_XDOTOOL xdotool)
if(LIVE_XVFB AND LIVE_XDOTOOL)
  # The real-time bounds are printed here, not held: see docs/live.md ("Timing") for why and for the run that holds
  # them (TIMING=1).
  add_test(NAME live_window_30fps
           COMMAND ${BLURCUE_EXPECT} "ok: live_test window" ${LIVE_TEST} window $<TARGET_FILE:blurcue> ${LIVE_DIR})
  set_tests_properties(live_window_30fps PROPERTIES FIXTURES_REQUIRED live_take LABELS "gl;window")
endif()
# bench live (issue 43, item 4) on 12 frames, N = 0, 4, 77 sections a frame: a row per N, and its values sane against
# what the runs must show whatever the machine's speed (tests/live_bench_check.py; no timing bound); its chart drawn.
add_test(NAME cli_bench_live_quick
         COMMAND ${BLURCUE_EXPECT} "wrote .*live.csv \\(3 rows\\).*77 sections a frame: latency [0-9.]+x the pose-only run's"
                 $<TARGET_FILE:blurcue> bench live --quick --out ${PROJECT_BINARY_DIR}/live-bench/live.csv)
set_tests_properties(cli_bench_live_quick PROPERTIES LABELS "slow;gl" FIXTURES_SETUP live_bench)
add_test(NAME cli_bench_live_values
         COMMAND ${BLURCUE_EXPECT} "ok: live_bench_check" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/live_bench_check.py
                 ${PROJECT_BINARY_DIR}/live-bench/live.csv)
set_tests_properties(cli_bench_live_values PROPERTIES FIXTURES_REQUIRED live_bench)
add_test(NAME cli_bench_live_chart
         COMMAND ${BLURCUE_EXPECT} "wrote .*bench-live.png" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/analysis/live_chart.py
                 ${PROJECT_BINARY_DIR}/live-bench/live.csv ${PROJECT_BINARY_DIR}/live-bench)
set_tests_properties(cli_bench_live_chart PROPERTIES FIXTURES_REQUIRED live_bench LABELS slow
                     WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}/analysis)
# Ctrl-C (SIGINT) ends a run cleanly, while it plays and while it preloads: exit 0, one line, the log whole
# (tests/live_interrupt_test.sh).
foreach(case play preload)
  add_test(NAME live_interrupted_${case}
           COMMAND ${BLURCUE_EXPECT} "ok: live_interrupt ${case}" bash ${PROJECT_SOURCE_DIR}/tests/live_interrupt_test.sh
                   $<TARGET_FILE:blurcue> ${LIVE_DIR} ${case})
  set_tests_properties(live_interrupted_${case} PROPERTIES FIXTURES_REQUIRED live_take LABELS gl)
endforeach()
# A frame of another size than camera.json says: one line naming the input, the frame and the camera.json, exit 3
# (it said "frame 0: frame 0: is 574x382 but the camera says 1148x764", naming neither file).
add_test(NAME live_frame_of_another_size_make
         COMMAND /usr/bin/python3 -c "import os, sys; from PIL import Image; os.makedirs(sys.argv[2], exist_ok=True); im = Image.open(sys.argv[1]); im.resize((im.width // 2, im.height // 2)).save(sys.argv[2] + '/frame-0000.png')"
                 ${LIVE_DIR}/take/frame-0000.png ${LIVE_DIR}/small)
set_tests_properties(live_frame_of_another_size_make PROPERTIES FIXTURES_REQUIRED live_take FIXTURES_SETUP live_small)
add_test(NAME live_frame_of_another_size
         COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue>
                 "-DARGS=live;${LIVE_DIR}/small/frame-%04d.png;--camera;${LIVE_DIR}/take/camera.json;--track;${LIVE_DIR}/track;--ball;87.5,125;--log;${LIVE_DIR}/small-log;--quiet"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=small/frame-%04d.png, frame 0: is 574x382 but the camera (${LIVE_DIR}/take/camera.json) says 1148x764"
                 -DONE_LINE=1 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(live_frame_of_another_size PROPERTIES FIXTURES_REQUIRED live_small LABELS gl)
# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(live_make 47 cli_bench_live_quick 30)
