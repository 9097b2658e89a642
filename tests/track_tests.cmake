# blurcue synth-take and blurcue track end to end (tests/track_test.sh); the tracker against a ground-truth take is
# src/track/tracker_test.cc.
add_test(NAME track_cli COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/track_test.sh $<TARGET_FILE:blurcue>
                                ${PROJECT_BINARY_DIR}/track-test)

# The track bench on 4 frames writes one row per (mode, frame) - track, track-inline, track-serial, detect, calibrate in process and
# calibrate run as a command - and says the targets and the measured ratio in words; its chart is drawn.
add_test(NAME cli_bench_track_quick
         COMMAND ${BLURCUE_EXPECT} "wrote .*track.csv \\(24 rows\\).*track +4 .*\\(3 tracked\\).*calibrate-process +4 .*track decoding the next frame meanwhile: [0-9.]+x.*track: median [0-9.]+ ms a frame wall.*track vs calibrate run as a command on each frame: [0-9.]+x faster" $<TARGET_FILE:blurcue> bench track --quick --out ${PROJECT_BINARY_DIR}/track-bench/track.csv)
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
# Issue 39: a JPEG image sequence with one frame cut at 75 % (it was tracked, exit 0): exit 3 naming the frame's file.
add_test(NAME track_cut_frame_make
         COMMAND ${BLURCUE_EXPECT} "ok: cut frame 1 of 3" sh -c "$<TARGET_FILE:blurcue> synth-take --out ${PROJECT_BINARY_DIR}/track-cut/take --frames 3 --quiet && /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/cut_images.py sequence ${PROJECT_BINARY_DIR}/track-cut/take/frame-%04d.png ${PROJECT_BINARY_DIR}/track-cut/jpeg/frame-%04d.jpg 1")
set_tests_properties(track_cut_frame_make PROPERTIES FIXTURES_SETUP track_cut)
add_test(NAME track_cut_frame
         COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue>
                 "-DARGS=track;${PROJECT_BINARY_DIR}/track-cut/jpeg/frame-%04d.jpg;--camera;${PROJECT_BINARY_DIR}/track-cut/take/camera.json;--out;${PROJECT_BINARY_DIR}/track-cut/track;--quiet"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=frame-0001.jpg: truncated JPEG"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(track_cut_frame PROPERTIES FIXTURES_REQUIRED track_cut)
# --fps is checked before any frame is read: 1e-300 wrote a 63-digit time, then was refused.
add_test(NAME track_fps_out_of_range
         COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue>
                 "-DARGS=track;${PROJECT_BINARY_DIR}/track-cut/take/frame-%04d.png;--camera;${PROJECT_BINARY_DIR}/track-cut/take/camera.json;--out;${PROJECT_BINARY_DIR}/track-cut/fps;--fps;1e-300"
                 -DEXPECT_CODE=2 "-DEXPECT_TEXT=--fps: must be in [0.01, 1000] frames per second, got 1e-300"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(track_fps_out_of_range PROPERTIES FIXTURES_REQUIRED track_cut)
# A tracked take read back (ar) refuses hand edits: a frame's lens model not the take's, a track.csv cut inside its
# last row, a board that is not the calibration's (tests/take_edits_check.py).
add_test(NAME track_cut_take_tracked
         COMMAND $<TARGET_FILE:blurcue> track ${PROJECT_BINARY_DIR}/track-cut/take/frame-%04d.png
                 --camera ${PROJECT_BINARY_DIR}/track-cut/take/camera.json --out ${PROJECT_BINARY_DIR}/track-cut/good --quiet)
set_tests_properties(track_cut_take_tracked PROPERTIES FIXTURES_REQUIRED track_cut FIXTURES_SETUP track_cut_good)
add_test(NAME track_read_back_edits
         COMMAND ${BLURCUE_EXPECT} "ok: a tracked take's hand edits are refused" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/take_edits_check.py $<TARGET_FILE:blurcue>
                 ${PROJECT_BINARY_DIR}/track-cut/take ${PROJECT_BINARY_DIR}/track-cut/good
                 ${PROJECT_BINARY_DIR}/track-cut/edits)
set_tests_properties(track_read_back_edits PROPERTIES FIXTURES_REQUIRED track_cut_good LABELS gl)
# ar --frames DIR replaces DIR whole when it holds ar's files only; a folder of one's own frame-NNNN.png images alone
# passed that check and was replaced, its images deleted. ar writes ar-frames.txt into every frames folder: a folder
# without it is refused before any work (exit 3), and one ar wrote is replaced by the next run.
set(AR_OWN ${PROJECT_BINARY_DIR}/track-cut/own-frames)
add_test(NAME ar_frames_own_images_make
         COMMAND ${CMAKE_COMMAND} -E copy ${PROJECT_BINARY_DIR}/track-cut/take/frame-0000.png ${AR_OWN}/frame-0000.png)
set_tests_properties(ar_frames_own_images_make PROPERTIES FIXTURES_REQUIRED track_cut FIXTURES_SETUP ar_own_frames)
set(AR_ARGS ar;${PROJECT_BINARY_DIR}/track-cut/take/frame-%04d.png;--track;${PROJECT_BINARY_DIR}/track-cut/good;--ball;87.5,125)
string(REPLACE ";" " " AR_WORDS "${AR_ARGS}")
add_test(NAME ar_frames_own_images_refused
         COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue> "-DARGS=${AR_ARGS};--out;${AR_OWN}.avi;--frames;${AR_OWN}"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=--frames ${AR_OWN}: holds no ar-frames.txt: not frames ar drew"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(ar_frames_own_images_refused PROPERTIES FIXTURES_REQUIRED "track_cut_good;ar_own_frames" LABELS gl)
add_test(NAME ar_frames_replaced_when_ars
         COMMAND ${BLURCUE_EXPECT} "^ar-frames.txt frame-0000.png frame-0001.png frame-0002.png END"
                 sh -c "set -e; B=${PROJECT_BINARY_DIR}/track-cut/ar-again; rm -rf $B $B.avi $B.csv; for i in 1 2; do $<TARGET_FILE:blurcue> ${AR_WORDS} --out $B.avi --frames $B --quiet; rm $B.avi $B.csv; done; ls $B | tr '\\n' ' '; echo END")
set_tests_properties(ar_frames_replaced_when_ars PROPERTIES FIXTURES_REQUIRED track_cut_good LABELS gl)
