# End-to-end tests of the blurcue executable: real files on disk, exit codes and one-line errors.
set(BC $<TARGET_FILE:blurcue>)
set(T ${PROJECT_BINARY_DIR}/cli-test)

# A small ground-truth scene shared by the calibrate tests.
add_test(NAME cli_synth_scene COMMAND ${BC} synth-scene --out ${T}/scene --seed 3 --noise 0.004)
set_tests_properties(cli_synth_scene PROPERTIES FIXTURES_SETUP scene)

add_test(NAME cli_calibrate_scene
         COMMAND ${BC} calibrate ${T}/scene/scene.png --camera ${T}/scene/camera.json
                 --truth ${T}/scene/truth.json --out ${T}/calib.json)
set_tests_properties(cli_calibrate_scene PROPERTIES FIXTURES_REQUIRED scene
                     PASS_REGULAR_EXPRESSION "board 7x10 found.*edge +u/mm")

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
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=bad-camera.json: /f_number: must be > 0, got 0"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(cli_calibrate_bad_camera PROPERTIES FIXTURES_REQUIRED scene)

# Unknown command: usage error, exit 2.
add_test(NAME cli_unknown_command
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=calibrat" -DEXPECT_CODE=2 "-DEXPECT_TEXT=calibrat"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)

# The measurement bench, two levels per factor, writes its CSV.
add_test(NAME cli_bench_measure_quick
         COMMAND ${BC} bench measure --quick --no-full-res --out ${T}/bench/measure.csv)
set_tests_properties(cli_bench_measure_quick PROPERTIES PASS_REGULAR_EXPRESSION "wrote .*measure.csv.*model_fit" LABELS slow)
