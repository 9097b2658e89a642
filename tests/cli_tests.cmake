# End-to-end tests of the blurcue executable: real files on disk, exit codes and one-line errors.
set(BC $<TARGET_FILE:blurcue>)
set(T ${PROJECT_BINARY_DIR}/cli-test)

# A small ground-truth scene shared by the calibrate tests.
add_test(NAME cli_synth_scene COMMAND ${BC} synth-scene --out ${T}/scene --seed 3 --noise 0.004)
set_tests_properties(cli_synth_scene PROPERTIES FIXTURES_SETUP scene)

add_test(NAME cli_calibrate_scene
         COMMAND ${BLURCUE_EXPECT} "board 7x10 found.*edge +u/mm" ${BC} calibrate ${T}/scene/scene.png --camera ${T}/scene/camera.json
                 --truth ${T}/scene/truth.json --out ${T}/calib.json)
set_tests_properties(cli_calibrate_scene PROPERTIES FIXTURES_REQUIRED scene FIXTURES_SETUP calib)

# No board in the photo: exit 4 and a line naming the photo.
add_test(NAME cli_calibrate_no_board
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=calibrate;${T}/scene/scene-no-board.png;--camera;${T}/scene/camera.json;--out;${T}/x.json"
                 -DEXPECT_CODE=4 "-DEXPECT_TEXT=scene-no-board.png: no 7x10 checkerboard found"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(cli_calibrate_no_board PROPERTIES FIXTURES_REQUIRED scene)

# A board of another size than the photo's.
add_test(NAME cli_calibrate_wrong_board
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=calibrate;${T}/scene/scene.png;--camera;${T}/scene/camera.json;--board;8x10;--out;${T}/x.json"
                 -DEXPECT_CODE=4 "-DEXPECT_TEXT=no 8x10 checkerboard found"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(cli_calibrate_wrong_board PROPERTIES FIXTURES_REQUIRED scene)

# A camera whose image size is not the photo's: exit 3 naming the camera file and the field.
add_test(NAME cli_calibrate_camera_mismatch
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=calibrate;${T}/scene/scene.png;--camera;${PROJECT_SOURCE_DIR}/tests/data/thesis-camera.json;--out;${T}/x.json"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=thesis-camera.json: camera /image_width_px"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(cli_calibrate_camera_mismatch PROPERTIES FIXTURES_REQUIRED scene)

# An unreadable photo: exit 3 naming the file.
file(WRITE ${PROJECT_BINARY_DIR}/cli-test-data/not-a-photo.png "hello")
add_test(NAME cli_calibrate_unreadable
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=calibrate;${PROJECT_BINARY_DIR}/cli-test-data/not-a-photo.png;--camera;${PROJECT_SOURCE_DIR}/tests/data/thesis-camera.json;--out;${T}/x.json"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=not-a-photo.png: not a readable image"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)

# A camera file with an impossible value.
file(WRITE ${PROJECT_BINARY_DIR}/cli-test-data/bad-camera.json
     "{\"focal_length_mm\": 21, \"f_number\": 0, \"sensor_width_mm\": 23.4, \"sensor_height_mm\": 15.6, \"image_width_px\": 1148, \"image_height_px\": 764}")
add_test(NAME cli_calibrate_bad_camera
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=calibrate;${T}/scene/scene.png;--camera;${PROJECT_BINARY_DIR}/cli-test-data/bad-camera.json;--out;${T}/x.json"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=bad-camera.json: /f_number: must be in [0.5, 256], got 0"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(cli_calibrate_bad_camera PROPERTIES FIXTURES_REQUIRED scene)

# Unknown command: usage error, exit 2.
add_test(NAME cli_unknown_command
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=calibrat" -DEXPECT_CODE=2 "-DEXPECT_TEXT=calibrat"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)

# The quick benches (measure, render, record, procedures) run in the demo (ctest `demo`), which charts them.

# Stimuli: one composited ball, a two-ball animation offscreen to video + log, and the same in a window under Xvfb.
add_test(NAME cli_render_ball
         COMMAND ${BLURCUE_EXPECT} "ball at edge 9: depth [0-9.]+ mm, blur estimated" ${BC} render --calib ${T}/calib.json --background ${T}/scene/scene.png --object ball --at-edge 9
                 --blur estimated --gain 2 --out ${T}/ball.png)
set_tests_properties(cli_render_ball PROPERTIES FIXTURES_REQUIRED "scene;calib" LABELS gl FIXTURES_SETUP render_ball)
add_test(NAME cli_render_bad_source
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=render;--calib;${T}/calib.json;--background;${T}/scene/scene.png;--blur;blurry;--out;${T}/x.png"
                 -DEXPECT_CODE=2 "-DEXPECT_TEXT=--blur: blur source must be none, measured, measured_section, estimated, fitted or a radius"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(cli_render_bad_source PROPERTIES FIXTURES_REQUIRED "scene;calib")
add_test(NAME cli_animate_video
         COMMAND ${BLURCUE_EXPECT} "16 frames \\(0.5 s of motion at 50.0 cm/s, 30 fps\\)" ${BC} animate --calib ${T}/calib.json --background ${T}/scene/scene.png --left measured --right none
                 --speed-cm-s 50 --fps 30 --video ${T}/anim.avi --log ${T}/anim.csv)
set_tests_properties(cli_animate_video PROPERTIES FIXTURES_REQUIRED "scene;calib" LABELS gl)
find_program(XVFB_RUN xvfb-run)
if(XVFB_RUN)
  add_test(NAME cli_animate_window
           COMMAND ${BLURCUE_EXPECT} "31 frames" ${XVFB_RUN} -a -s "-screen 0 1280x1024x24" ${BC} animate --calib ${T}/calib.json
                   --background ${T}/scene/scene.png --left estimated --right none --speed-cm-s 50 --window
                   --log ${T}/window.csv)
  set_tests_properties(cli_animate_window PROPERTIES FIXTURES_REQUIRED "scene;calib" LABELS "gl;window")
endif()
add_test(NAME cli_blur_image
         COMMAND ${BLURCUE_EXPECT} "disc \\(gl, 800x1200\\)" ${BC} blur ${PROJECT_SOURCE_DIR}/stimuli/face.png --method disc --radius-px 6 --backend gl
                 --out ${T}/face-r6.png)
set_tests_properties(cli_blur_image PROPERTIES LABELS gl FIXTURES_SETUP blur_image)
# The images those commands wrote, on their pixels (tests/image_check.py): the blur against a pillbox worked out apart
# from blurcue (a radius 10 % off fails), the ball as one compact object over an otherwise untouched photo.
add_test(NAME cli_blur_image_pixels
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/image_check.py disc ${PROJECT_SOURCE_DIR}/stimuli/face.png
                 ${T}/face-r6.png 6)
set_tests_properties(cli_blur_image_pixels PROPERTIES FIXTURES_REQUIRED blur_image)
add_test(NAME cli_render_ball_pixels
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/image_check.py drawn ${T}/scene/scene.png ${T}/ball.png)
set_tests_properties(cli_render_ball_pixels PROPERTIES FIXTURES_REQUIRED render_ball)
add_test(NAME cli_render_picture
         COMMAND ${BLURCUE_EXPECT} "picture face, cut-off 6 cycles per picture width" ${BC} render --object picture --cutoff 6 --background ${T}/scene/scene.png --out ${T}/picture.png)
set_tests_properties(cli_render_picture PROPERTIES FIXTURES_REQUIRED scene)

# What FULL durability costs per answer: both arms measured in one run, the ratio printed.
add_test(NAME cli_bench_record COMMAND ${BLURCUE_EXPECT} "synchronous=FULL +median [0-9.]+ ms.*synchronous=NORMAL +median [0-9.]+ ms.*FULL costs" ${BC} bench record --trials 20 --folder ${T}/bench-record)

# Which procedure: 40 seeded runs each; the CSV must show what the procedures are known to do - every one gets
# better with trials for a nominal observer, QUEST+ is the least biased and the first within 10 % RMSE there, and a
# side bias or a threshold beyond the stimulus range defeats the adaptive ones (tests/procedure_bench_check.py). A
# second run with another seed checks the rows' Monte Carlo standard errors against the spread between the two runs.
add_test(NAME cli_bench_procedures
         COMMAND ${BLURCUE_EXPECT} "wrote .*procedures.csv \\(80 rows" ${BC} bench procedures --quick --out ${T}/bench/procedures.csv)

add_test(NAME cli_bench_procedures_seed2
         COMMAND ${BC} bench procedures --quick --seed 2 --out ${T}/bench/procedures-seed2.csv)
add_test(NAME cli_bench_procedures_check
         COMMAND ${BLURCUE_EXPECT} "ok: " /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/procedure_bench_check.py ${T}/bench/procedures.csv
                 ${T}/bench/procedures-seed2.csv)
# Ordered by fixtures (DEPENDS only orders when both run: ctest -R check alone found no CSV and failed).
set_tests_properties(cli_bench_procedures cli_bench_procedures_seed2 PROPERTIES FIXTURES_SETUP bench_procedures)
set_tests_properties(cli_bench_procedures_check PROPERTIES FIXTURES_REQUIRED bench_procedures)

# blurcue camera: camera.json from EXIF that Pillow wrote (focal-plane resolution, the sensor table, the 35 mm
# equivalent, a photo stored turned), and missing tags refused naming the tag and the option.
add_test(NAME cli_camera_exif
         COMMAND ${BLURCUE_EXPECT} "ok: camera.json from EXIF" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/camera_exif_test.py ${BC} ${T}/camera-exif)

# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(cli_camera_exif 13)

# blurcue make-stimuli: its textures against their geometry worked out apart from it (tests/stimuli_check.py): the
# grid's 6 x 6 bands, the soccer ball's 12 spherical pentagons (share of the sphere by spherical excess, each 63.43 deg
# from 5 others), the face's alpha.
add_test(NAME cli_make_stimuli
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/stimuli_check.py ${BC} ${T}/make-stimuli)

# Issue 39: a damaged image is refused, not read with grey fill. The scene's photo as a JPEG cut at 75 % of its bytes
# (it still decoded, rows below the cut grey, and calibrated with exit 0): exit 3 naming the file and why.
add_test(NAME cli_cut_jpeg_make
         COMMAND ${BLURCUE_EXPECT} "ok: cut" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/cut_images.py photo ${T}/scene/scene.png ${T}/cut/scene-cut.jpg)
set_tests_properties(cli_cut_jpeg_make PROPERTIES FIXTURES_REQUIRED scene FIXTURES_SETUP cut_jpeg)
add_test(NAME cli_calibrate_cut_jpeg
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=calibrate;${T}/cut/scene-cut.jpg;--camera;${T}/scene/camera.json;--out;${T}/cut/calib.json"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=scene-cut.jpg: truncated JPEG" -DONE_LINE=1
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(cli_calibrate_cut_jpeg PROPERTIES FIXTURES_REQUIRED cut_jpeg)

# --- mends. The fitted aperture 0.74 x and 1.30-1.31 x the nominal (camera.json at f/4 and f/7.1 for a scene taken at
# f/5.6) passed without a word under the old bound of 2 x: now the warning and the summary say it, beyond two thirds
# of a stop either way.
set(MENDS_SENSOR "\"focal_length_mm\": 21, \"sensor_width_mm\": 23.4, \"sensor_height_mm\": 15.6, \"image_width_px\": 1148, \"image_height_px\": 764")
foreach(pair "4;0.7[0-9]*;5.250" "7.1;1.3[0-9]*;2.958")
  list(GET pair 0 n)
  list(GET pair 1 ratio)
  list(GET pair 2 nominal)
  file(WRITE ${T}/mends/camera-f${n}.json "{\"f_number\": ${n}, ${MENDS_SENSOR}}")
  add_test(NAME cli_calibrate_aperture_warn_f${n}
           COMMAND ${BLURCUE_EXPECT} "warning: .*scene.png: the fitted aperture 3.[0-9]+ mm is ${ratio} x the camera's \\(${nominal} mm, f/${n}\\), more than two thirds of a stop off.*aperture 3.[0-9]+ mm \\(nominal ${nominal}, ${ratio} x: more than two thirds of a stop off\\)"
                   ${BC} calibrate ${T}/scene/scene.png --camera ${T}/mends/camera-f${n}.json --out ${T}/mends/calib-f${n}.json)
  set_tests_properties(cli_calibrate_aperture_warn_f${n} PROPERTIES FIXTURES_REQUIRED scene)
endforeach()
# A first-time experimenter's scene: sharpened after sampling (mask of amount 0.5 over 0.8 px), focus 300 mm in front of
# the board, printing flaws. The aperture came out 1.40 x and the warning blamed covered edges or the f-number, not
# the sharpening the phase check had found; the summary never said what poor_fit or the flaws meant, nor that the
# table's thesis column is the thesis's pixel count (several px over the optical blur). Since the sections over 2 px
# are read with the chosen mask (phase_check.h, PhaseCheck::wide) that scene's aperture was 1.23 x, so the scene
# became a mask of amount 0.7 over 0.8 px: 1.44 x, then 1.33 x with the warning naming the sharpening. Since the
# sections the mask cancels to 0 px are bounds, not values (PhaseCheck::bound, model.cancel_px2), the lens is fitted
# right there: focus 305 mm for 300, aperture 1.05 x, and no warning (the output starts with the board; a warning
# would come first).
add_test(NAME cli_calibrate_sharpened_scene_make
         COMMAND ${BC} synth-scene --out ${T}/sharpened --seed 3 --noise 0.003 --focus-mm 300 --flaws 20
                 --post-filter sharpen --post-sigma-px 0.8 --post-amount 0.7 --quiet)
set_tests_properties(cli_calibrate_sharpened_scene_make PROPERTIES FIXTURES_SETUP sharpened)
add_test(NAME cli_calibrate_sharpened_fits_the_lens
         COMMAND ${BLURCUE_EXPECT} "^board 7x10 found.*\nfitted thin_lens(\\+floor)? model: focus 30[0-9]\\.[0-9] mm, aperture 3\\.[7-9][0-9]* mm \\(nominal 3.750\\).*\n[0-9]+ sections flagged flaw: printing spots near the edge, left out of the profile \\(the section is used\\).*\nmeasured: the mean r_px of the edge's usable sections and of those pooled into the lens fit, the value blur source .measured. draws there.*; thesis: the thesis's pixel count"
                 ${BC} calibrate ${T}/sharpened/scene.png --camera ${T}/sharpened/camera.json --out ${T}/sharpened-calib.json)
set_tests_properties(cli_calibrate_sharpened_fits_the_lens PROPERTIES FIXTURES_REQUIRED sharpened)
# animate --video killed midway left half a video under its final name: now it leaves the earlier one unchanged, and
# the next run removes the partial folder (tests/animate_kill_test.sh).
add_test(NAME cli_animate_video_killed
         COMMAND ${BLURCUE_EXPECT} "ok: a killed animate --video left the earlier video unchanged"
                 bash ${PROJECT_SOURCE_DIR}/tests/animate_kill_test.sh ${BC} ${T}/calib.json ${T}/scene/scene.png ${T}/animate-kill)
set_tests_properties(cli_animate_video_killed PROPERTIES FIXTURES_REQUIRED "scene;calib" LABELS gl)

# 'blurcue --help' lists each command by its first sentence: every one whole, none cut to " ..." or ending at a colon
# (make-stimuli's ended "PNG):", preview's and eight others' " ...").
add_test(NAME cli_help_whole_first_sentences
         COMMAND ${BLURCUE_EXPECT} "\n  make-stimuli +Draw the study's stimulus textures \\(procedural, deterministic, 8-bit sRGB PNG\\)\\.\n.*\n  preview +Draw a contact sheet of every distinct stimulus a protocol shows, to check the protocol by eye before a session\\.\n"
                 ${BC} --help)
set_tests_properties(cli_help_whole_first_sentences PROPERTIES
                     FAIL_REGULAR_EXPRESSION "\n  [a-z-]+  +[^\n]*(\\.\\.\\.|:)\n")
