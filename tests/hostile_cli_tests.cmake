# Hostile command lines, files and images (issue 9): every one ends in one line on stderr naming the option or
# file, the field and the value, and exit 2 (command line) or 3 (file) - never a signal, exit 10, a hang or an
# output written as if nothing were wrong. tests/data/make_hostile_images.py wrote the PNGs.
set(D ${PROJECT_SOURCE_DIR}/tests/data)
set(H ${PROJECT_BINARY_DIR}/cli-test-hostile)
file(MAKE_DIRECTORY ${H})

# hostile_test(NAME CODE TEXT ARG...): blurcue ARG... exits CODE with exactly one stderr line containing TEXT.
function(hostile_test name code text)
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue> "-DARGS=${ARGN}" -DEXPECT_CODE=${code}
                   "-DEXPECT_TEXT=${text}" -DONE_LINE=1 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
endfunction()

# blur: NaN, huge, infinite and negative radii on both back ends (the CPU path used to crash, GL to hang or to
# write the image unblurred).
foreach(backend cpu gl)
  # Text that is no decimal number is quoted as typed; a number out of range is not.
  foreach(pair "nan;nan;'nan'" "1e308;1e308;1e308" "1e9;1e9;1e9" "inf;inf;'inf'" "minus1;-1;-1")
    list(GET pair 0 tag)
    list(GET pair 1 value)
    list(GET pair 2 shown)
    hostile_test(cli_hostile_blur_${backend}_radius_${tag} 2 "--radius-px: must be in [0, 500] px, got ${shown}"
                 blur ${D}/small.png --backend ${backend} --radius-px=${value} --out ${H}/x.png)
  endforeach()
endforeach()
hostile_test(cli_hostile_blur_radius_not_a_number 2 "--radius-px: must be in [0, 500] px, got '3px'"
             blur ${D}/small.png --radius-px 3px --out ${H}/x.png)
# An image name no encoder writes was refused only after the work, exit 3, naming no option ("cannot encode an image
# as ''"): now before it, exit 2, naming the option.
hostile_test(cli_hostile_blur_out_no_extension 2 "--out ${H}/blurred: no image can be written as ''"
             blur ${D}/small.png --radius-px 2 --out ${H}/blurred)
hostile_test(cli_hostile_preview_out_unknown_extension 2 "--out ${H}/sheet.xyz: no image can be written as '.xyz': name the file .png"
             preview ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --out ${H}/sheet.xyz)
hostile_test(cli_hostile_blur_cutoff_nan 2 "--cutoff: must be in (0, 100000] cycles per image width, got 'nan'"
             blur ${D}/small.png --method butterworth --cutoff nan --out ${H}/x.png)
hostile_test(cli_hostile_blur_cutoff_zero 2 "--cutoff: must be in (0, 100000] cycles per image width, got 0"
             blur ${D}/small.png --method butterworth --cutoff 0 --out ${H}/x.png)
# The other method's value is refused, not ignored (a Butterworth given --radius-px blurred by its cut-off alone).
hostile_test(cli_hostile_blur_cutoff_on_gaussian 2 "--cutoff: is for --method butterworth; gaussian reads --radius-px"
             blur ${D}/small.png --radius-px 2 --cutoff 3 --out ${H}/x.png)
hostile_test(cli_hostile_blur_radius_on_butterworth 2 "--radius-px: is for --method gaussian or disc; butterworth reads --cutoff"
             blur ${D}/small.png --method butterworth --cutoff 3 --radius-px 2 --out ${H}/x.png)

# Images that are no image: a device, a directory, a header claiming 65535 x 65535 px, a truncated PNG.
hostile_test(cli_hostile_image_dev_zero 3 "IN /dev/zero: is a character device, not a file; not read"
             blur /dev/zero --radius-px 2 --out ${H}/x.png)
hostile_test(cli_hostile_image_directory_option 2 "File is actually a directory: ${D}"
             blur ${D} --radius-px 2 --out ${H}/x.png)
hostile_test(cli_hostile_image_directory 3 "${D}: is a directory, not an image file"
             render --object picture:${D} --background ${D}/small.png --out ${H}/x.png)
hostile_test(cli_hostile_image_huge_header 3
             "huge-header.png: is 65535 x 65535 px; images are read up to 20000 px a side and 120 Mpx"
             blur ${D}/huge-header.png --backend cpu --radius-px 2 --out ${H}/x.png)
hostile_test(cli_hostile_image_truncated 3 "bad-iccp-truncated.png: truncated PNG"
             blur ${D}/bad-iccp-truncated.png --backend cpu --radius-px 2 --out ${H}/x.png)
# A valid PNG with a broken iCCP profile: libpng's warning must not reach stderr.
add_test(NAME cli_hostile_image_bad_iccp_is_quiet
         COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue>
                 "-DARGS=blur;${D}/bad-iccp.png;--backend;cpu;--radius-px;2;--out;${H}/iccp.png"
                 "-DEXPECT_TEXT=gaussian (cpu, 16x12) -> ${H}/iccp.png"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_quiet_success.cmake)

# render: a fixed radius of 1e9 and a NaN gain used to write the photo without the object and exit 0.
hostile_test(cli_hostile_render_blur_1e9 2
             "--blur: blur source must be none, measured, measured_section, estimated, fitted or a radius in [0, 500] px, got '1e9'"
             render --calib ${T}/calib.json --background ${T}/scene/scene.png --blur 1e9 --out ${H}/x.png)
hostile_test(cli_hostile_render_gain_nan 2 "--gain: must be a number in [0, 100], got 'nan'"
             render --calib ${T}/calib.json --background ${T}/scene/scene.png --gain nan --out ${H}/x.png)
set_tests_properties(cli_hostile_render_blur_1e9 cli_hostile_render_gain_nan PROPERTIES
                     FIXTURES_REQUIRED "scene;calib")
hostile_test(cli_hostile_render_radius_times_gain 2
             "--blur 400 x --gain 2 gives 800 px at the object; the blur radius must be in [0, 500] px"
             render --calib ${T}/calib.json --background ${T}/scene/scene.png --blur 400 --gain 2 --out ${H}/x.png)
set_tests_properties(cli_hostile_render_radius_times_gain PROPERTIES FIXTURES_REQUIRED "scene;calib" LABELS gl)
# A radius the calibration gives (a hand-edited floor of 500 px): the message names the file and its field, not only
# the options (it blamed `--blur fitted x --gain 1`).
add_test(NAME cli_hostile_render_floor_500_make
         COMMAND /usr/bin/python3 -c "import json, sys; c = json.load(open(sys.argv[1])); c['model'].update(kind='thin_lens+floor', floor_px=500, floor_determined=True); json.dump(c, open(sys.argv[2], 'w'))"
                 ${T}/calib.json ${H}/calib-floor-500.json)
set_tests_properties(cli_hostile_render_floor_500_make PROPERTIES FIXTURES_REQUIRED "scene;calib" FIXTURES_SETUP floor_500)
hostile_test(cli_hostile_render_floor_500_names_file 2
             "px at the object (the lens model, ${H}/calib-floor-500.json /model); the blur radius must be in [0, 500] px"
             render --calib ${H}/calib-floor-500.json --background ${T}/scene/scene.png --at-edge 2 --blur fitted --out ${H}/x.png)
set_tests_properties(cli_hostile_render_floor_500_names_file PROPERTIES
                     FIXTURES_REQUIRED "scene;calib;floor_500")
hostile_test(cli_hostile_render_cutoff_nan 2 "--cutoff: must be in [0, 100000] cycles per picture width, got 'nan'"
             render --object picture --background ${D}/small.png --cutoff nan --out ${H}/x.png)
# --object is read whole ("balloon" and "ball:" were drawn as the soccer ball, "picturesque" as the face), and an option
# the object does not read is refused, not ignored (a --cutoff on a ball, a --blur on the picture; the calibration is
# not read before the refusal).
hostile_test(cli_hostile_render_object_unknown 2 "--object must be grid, ball[:TEXTURE] or picture[:IMAGE], got 'balloon'"
             render --calib ${D}/thesis-camera.json --background ${D}/small.png --object balloon --out ${H}/x.png)
hostile_test(cli_hostile_render_object_empty_texture 2 "--object must be grid, ball[:TEXTURE] or picture[:IMAGE], got 'ball:'"
             render --calib ${D}/thesis-camera.json --background ${D}/small.png --object ball: --out ${H}/x.png)
hostile_test(cli_hostile_render_cutoff_on_ball 2 "--cutoff: is for a picture, not --object ball (nothing reads it)"
             render --calib ${D}/thesis-camera.json --background ${D}/small.png --cutoff 5 --out ${H}/x.png)
hostile_test(cli_hostile_render_blur_on_picture 2 "--blur: is for a grid or a ball, not --object picture (nothing reads it)"
             render --object picture --background ${D}/small.png --blur 3 --out ${H}/x.png)
hostile_test(cli_hostile_render_section_on_grid 2 "--section: is for a ball, not --object grid (nothing reads it)"
             render --calib ${D}/thesis-camera.json --background ${D}/small.png --object grid --section 2 --out ${H}/x.png)

# camera.json: a width of 2^32 + 1148 used to wrap to 1148 and calibrate; every number has a physical range.
set(CAMERA_REST "\"sensor_width_mm\": 23.4, \"sensor_height_mm\": 15.6, \"image_height_px\": 764")
file(WRITE ${H}/camera-wrapped-width.json
     "{\"focal_length_mm\": 21, \"f_number\": 5.6, ${CAMERA_REST}, \"image_width_px\": 4294968444}")
file(WRITE ${H}/camera-nan-focal.json
     "{\"focal_length_mm\": \"nan\", \"f_number\": 5.6, ${CAMERA_REST}, \"image_width_px\": 1148}")
file(WRITE ${H}/camera-negative-f-number.json
     "{\"focal_length_mm\": 21, \"f_number\": -5.6, ${CAMERA_REST}, \"image_width_px\": 1148}")
file(WRITE ${H}/camera-huge-focal.json
     "{\"focal_length_mm\": 1e308, \"f_number\": 5.6, ${CAMERA_REST}, \"image_width_px\": 1148}")
hostile_test(cli_hostile_camera_wrapped_width 3
             "camera-wrapped-width.json: /image_width_px: must be in [1, 20000] px, got 4294968444"
             calibrate ${T}/scene/scene.png --camera ${H}/camera-wrapped-width.json --out ${H}/calib.json)
set_tests_properties(cli_hostile_camera_wrapped_width PROPERTIES FIXTURES_REQUIRED scene)
set(ESTIMATE_ARGS --ref-u-mm 342.3 --ref-r-px 8 --u-mm 527.3)
hostile_test(cli_hostile_camera_nan_focal 3 "camera-nan-focal.json: /focal_length_mm: must be a number, got \"nan\""
             estimate --camera ${H}/camera-nan-focal.json ${ESTIMATE_ARGS})
hostile_test(cli_hostile_camera_negative_f_number 3
             "camera-negative-f-number.json: /f_number: must be in [0.5, 256], got -5.6"
             estimate --camera ${H}/camera-negative-f-number.json ${ESTIMATE_ARGS})
hostile_test(cli_hostile_camera_huge_focal 3
             "camera-huge-focal.json: /focal_length_mm: must be in [0.5, 2000] mm, got 1e+308"
             estimate --camera ${H}/camera-huge-focal.json ${ESTIMATE_ARGS})

# The numeric options of the other commands: each names its range and unit.
# camera's options hold the ranges camera.json does: a focal length of 0.001 mm passed the option's (0, 2000] and was
# refused afterwards naming the photo ("scene.png: /focal_length_mm: must be in [0.5, 2000] mm").
hostile_test(cli_hostile_camera_focal_length_tiny 2 "--focal-length-mm: must be in [0.5, 2000] mm, got 0.001"
             camera ${D}/small.png --sensor-mm 23.4 15.6 --focal-length-mm 0.001 --f-number 5.6)
hostile_test(cli_hostile_estimate_u_nan 2 "--u-mm: must be in (0, 1000000] mm, got 'nan'"
             estimate --camera ${D}/thesis-camera.json --ref-u-mm 342.3 --ref-r-px 8 --u-mm nan)
hostile_test(cli_hostile_estimate_ref_u_inf 2 "--ref-u-mm: must be in [0, 1000000] mm, got 'inf'"
             estimate --camera ${D}/thesis-camera.json --ref-u-mm inf --ref-r-px 8 --u-mm 500)
hostile_test(cli_hostile_synth_scene_width_wraps 2 "--width: must be a whole number in [32, 20000] px, got 4294968444"
             synth-scene --out ${H}/scene --width 4294968444)
hostile_test(cli_hostile_synth_scene_supersample_cap 2
             "--supersample: 1148 x 764 px at 16 x 16 sub-pixels is 224.53 M sub-pixels; the most a scene renders is 64 M"
             synth-scene --out ${H}/scene --supersample 16)
hostile_test(cli_hostile_synth_scene_focus_nan 2 "--focus-mm: must be a distance in (0, 1000000] mm or 'inf', got 'nan'"
             synth-scene --out ${H}/scene --focus-mm nan)
hostile_test(cli_hostile_synth_scene_noise_nan 2 "--noise: must be in [0, 1] linear units, got 'nan'"
             synth-scene --out ${H}/scene --noise nan)
# A post filter's option without that filter would be ignored: refused.
hostile_test(cli_hostile_synth_scene_post_sigma_without_filter 2 "--post-sigma-px: needs --post-filter gaussian or sharpen"
             synth-scene --out ${H}/scene --post-sigma-px 0.5)
hostile_test(cli_hostile_synth_scene_post_amount_gaussian 2 "--post-amount: is for --post-filter sharpen, not gaussian"
             synth-scene --out ${H}/scene --post-filter gaussian --post-amount 0.3)
# --post-amount alone named gaussian as a filter it would do for (it is sharpen's alone), and a filter given without
# its values quoted the unset default ("--post-sigma-px: must be in (0, 5] px with a post filter, got 0").
hostile_test(cli_hostile_synth_scene_post_amount_without_filter 2 "--post-amount: needs --post-filter sharpen (the filter is none)"
             synth-scene --out ${H}/scene --post-amount 0.3)
hostile_test(cli_hostile_synth_scene_post_filter_without_sigma 2 "--post-filter gaussian: needs --post-sigma-px S"
             synth-scene --out ${H}/scene --post-filter gaussian)
hostile_test(cli_hostile_synth_scene_sharpen_without_amount 2 "--post-filter sharpen: needs --post-amount A"
             synth-scene --out ${H}/scene --post-filter sharpen --post-sigma-px 0.6)
hostile_test(cli_hostile_synth_scene_seed_negative 2 "--seed: must be a whole number from 0 to 18446744073709551615, got '-3'"
             synth-scene --out ${H}/scene --seed=-3)
hostile_test(cli_hostile_synth_pictures_focus_inf 2 "--focus-m: must be in (0, 1000] m, got 'inf'"
             synth-pictures --camera ${D}/thesis-camera.json --distances-m 1 --focus-m inf --out ${H}/pictures)
hostile_test(cli_hostile_synth_pictures_no_camera 2 "give --camera, or a --protocol whose content.real_camera names one"
             synth-pictures --distances-m 1 --out ${H}/pictures)
hostile_test(cli_hostile_calibrate_square_nan 2 "--square-mm: must be in [1, 1000] mm, got 'nan'"
             calibrate ${D}/small.png --camera ${D}/thesis-camera.json --square-mm nan)
hostile_test(cli_hostile_animate_fps_nan 2 "--fps: must be in [1, 1000] frames per second, got 'nan'"
             animate --calib ${D}/thesis-camera.json --background ${D}/small.png --fps nan --video ${H}/x.avi)
hostile_test(cli_hostile_run_sim_fps_nan 2 "--sim-fps: must be in [0.1, 1000] frames per second, got 'nan'"
             run ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --participant P1 --db ${H}/x.sqlite
             --observer sim --sim-fps nan)
hostile_test(cli_hostile_run_sim_fps_alone 2 "--sim-fps requires --observer"
             run ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --participant P1 --db ${H}/x.sqlite
             --sim-fps 30)
hostile_test(cli_hostile_validate_visible_alone 2 "--visible requires --plan"
             validate ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --visible 0.7)
hostile_test(cli_hostile_run_stop_after_negative 2 "--stop-after: must be a whole number in [0, 1000000], got -5"
             run ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --participant P1 --db ${H}/x.sqlite
             --stop-after=-5)
hostile_test(cli_hostile_report_boot_huge 2 "--boot: must be a whole number in [10, 100000], got '1e9'"
             report --db ${D}/small.png --out ${H}/report --boot 1e9)
hostile_test(cli_hostile_bench_seed_negative 2 "--seed: must be a whole number from 0 to 18446744073709551615"
             bench measure --seed=-3)
hostile_test(cli_hostile_preview_columns_octal_looking 2 "--columns: must be a whole number in [1, 20], got '0x10'"
             preview ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --out ${H}/x.png --columns 0x10)
hostile_test(cli_hostile_board_wraps 2 "--board: expected COLSxROWS in squares such as 7x10, got '4294967303x10'"
             synth-scene --out ${H}/scene --board 4294967303x10)
hostile_test(cli_hostile_board_too_many_squares 2 "--board 500x10: a board needs 2 to 100 squares a side"
             synth-scene --out ${H}/scene --board 500x10)
# A distance just beyond the focal length: a model limit (exit 5), said before it reaches an int or an allocation.
hostile_test(cli_hostile_synth_pictures_at_focal_length 5 "would be imaged"
             synth-pictures --camera ${D}/thesis-camera.json --distances-m 0.021001 --out ${H}/pictures)
hostile_test(cli_hostile_render_picture_taller_than_frame 2
             "--picture-height-px 5000 is taller than the grey half of the frame (360 px)"
             render --object picture --background ${D}/small.png --picture-height-px 5000 --out ${H}/x.png)
hostile_test(cli_hostile_sessions_abort_wraps 2
             "--abort: must be a whole number in [1, 9223372036854775807], got 18446744073709551617"
             sessions --db ${D}/small.png --abort 18446744073709551617)
hostile_test(cli_hostile_display_frames_nan 2 "--frames: must be a whole number in [10, 100000], got 'nan'"
             display check --frames nan)
# The simulated observer's parameters (issue 14): NaN, huge, negative and empty values, the other model's names, and
# the visibility level of validate --plan and preview - one line naming the parameter and the value, exit 2, before
# any file is read.
hostile_test(cli_hostile_observer_weber_nan 2 "--observer weber must be a number, got 'nan'"
             run ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --participant P1 --db ${H}/x.sqlite
             --observer sim:weber=nan)
hostile_test(cli_hostile_observer_intrinsic_huge 2 "--observer intrinsic must be in (0, 60] arcmin (a Gaussian std), got '1e308'"
             run ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --participant P1 --db ${H}/x.sqlite
             --observer sim:intrinsic=1e308)
hostile_test(cli_hostile_observer_lapse_negative 2 "--observer lapse must be in 0..1, got '-1'"
             run ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --participant P1 --db ${H}/x.sqlite
             --observer sim:lapse=-1)
hostile_test(cli_hostile_observer_rt_empty 2 "--observer rt must be a number, got ''"
             run ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --participant P1 --db ${H}/x.sqlite
             --observer sim:rt=)
hostile_test(cli_hostile_observer_other_model 2 "--observer jnd belongs to model=pixel, not model=arcmin"
             validate ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --plan --observer sim:model=arcmin,jnd=1)
hostile_test(cli_hostile_validate_visible_nan 2 "--visible: must be in [0.5, 1] share correct, got 'nan'"
             validate ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --plan --visible nan)
hostile_test(cli_hostile_preview_observer_model 2 "--observer model must be arcmin or pixel, got 'eye'"
             preview ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --out ${H}/x.png --observer sim:model=eye)

# Outputs that are not regular files: an atomic write renames over its target, so a FIFO (or, as root, a device
# such as /dev/full) would be replaced by a plain file; opening a FIFO to write waits for a reader forever. A FIFO
# made here stands for them all (a test must not risk /dev/null on the machine that runs it).
execute_process(COMMAND mkfifo ${H}/fifo.png ${H}/fifo.csv RESULT_VARIABLE ignored ERROR_QUIET)
hostile_test(cli_hostile_out_is_a_fifo 3 "fifo.png: is a FIFO, not a file"
             blur ${D}/small.png --radius-px 2 --out ${H}/fifo.png)
set(C ${PROJECT_BINARY_DIR}/cli-test)
set(ANIMATE animate --calib ${C}/calib.json --background ${C}/scene/scene.png --left estimated --right none
            --speed-cm-s 50 --fps 10)
hostile_test(cli_hostile_animate_log_is_a_fifo 3 "fifo.csv: is not a regular file" ${ANIMATE} --video ${H}/v.avi
             --log ${H}/fifo.csv)
hostile_test(cli_hostile_animate_video_not_avi 2 "--video ${H}/v.mp4: must end in .avi" ${ANIMATE} --video ${H}/v.mp4)
# A blur source the command cannot read names the option it came from (it named none: "blur source must be ...").
hostile_test(cli_hostile_animate_right_blur_negative 2 "--right: blur source must be" animate --calib ${C}/calib.json
             --background ${C}/scene/scene.png --left estimated --right=-1 --video ${H}/v.avi)
# --fullscreen without --window was ignored.
hostile_test(cli_hostile_animate_fullscreen_without_window 2 "--fullscreen requires --window" ${ANIMATE} --fullscreen
             --video ${H}/v.avi)
set_tests_properties(cli_hostile_animate_log_is_a_fifo cli_hostile_animate_video_not_avi
                     cli_hostile_animate_right_blur_negative cli_hostile_animate_fullscreen_without_window PROPERTIES
                     FIXTURES_REQUIRED "scene;calib" TIMEOUT 60)

# plan: a condition without one decisive answer (every simulated answer can't tell; one participant, seed 1: edges 1
# and 3 on the CLI tests' scene) has no share: its share and its Wilson width are "-", not "nan" and 1.000.
add_test(NAME cli_hostile_plan_no_share_is_no_nan
         COMMAND ${BLURCUE_EXPECT} "edge=[0-9]+ +first_source +- +- +0.000"
                 $<TARGET_FILE:blurcue> plan ${T}/protocols/test1-static-grids.json --participants 1 --studies 2
                 --no-chart --out ${H}/plan-no-share)
set_tests_properties(cli_hostile_plan_no_share_is_no_nan PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                     LABELS plan)

# report --out an earlier report replaced it whole, with whatever someone had put into it (notes.txt here; a report
# made inside it, rep/sub, went too): a report replaces only a folder of its own files (index.html, bench.html, charts,
# their tables, tables/ as export writes it).
add_test(NAME cli_hostile_report_own_file_make
         COMMAND bash -c "rm -rf '${H}/report-own' '${H}/report-own.sqlite' && '$<TARGET_FILE:blurcue>' run '${T}/protocols/test1-static-grids.json' --participant P1 --db '${H}/report-own.sqlite' --observer sim --stop-after 1 && mkdir -p '${H}/report-own' && touch '${H}/report-own/index.html' && echo notes > '${H}/report-own/notes.txt'")
set_tests_properties(cli_hostile_report_own_file_make PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                     FIXTURES_SETUP report_own)
hostile_test(cli_hostile_report_own_file_kept 3
             "report-own: holds notes.txt, which this command did not write; the folder is replaced as a whole"
             report --db ${H}/report-own.sqlite --out ${H}/report-own)
set_tests_properties(cli_hostile_report_own_file_kept PROPERTIES FIXTURES_REQUIRED report_own LABELS analysis)

# The same for plan --out: an earlier plan with a file put beside it (plan.csv and notes.txt) is refused, not replaced.
add_test(NAME cli_hostile_plan_own_file_make
         COMMAND bash -c "rm -rf '${H}/plan-own' && mkdir -p '${H}/plan-own' && touch '${H}/plan-own/plan.csv' && echo notes > '${H}/plan-own/notes.txt'")
set_tests_properties(cli_hostile_plan_own_file_make PROPERTIES FIXTURES_SETUP plan_own)
hostile_test(cli_hostile_plan_own_file_kept 3
             "plan-own: holds notes.txt, which this command did not write; the folder is replaced as a whole"
             plan ${T}/protocols/test1-static-grids.json --participants 1 --studies 1 --no-chart --out ${H}/plan-own)
set_tests_properties(cli_hostile_plan_own_file_kept PROPERTIES
                     FIXTURES_REQUIRED "plan_own;scene;calib;session_protocols" LABELS plan)

# What a trial shows must be drawable on its screen: a radius or a motion streak past the renderer's largest blur
# (500 screen px) validated, and run stopped at that trial with "blur radius must be in [0, 500] px, got 800", exit 5,
# naming no file (a fixed 100 photo px at display.scale 8; a ball at 100 cm/s under a 1 s exposure; a staircase whose
# max of 10 makes a 100 px reference 1100 photo px, 550 on the screen at scale 0.5). validate and run now refuse it,
# exit 3, naming the field.
set(SCREEN_PROTOCOL_REST "\"version\": 1, \"task\": \"forced_choice\",
 \"scene\": {\"background\": \"${T}/scene/scene.png\", \"calib\": \"${T}/calib.json\", \"show\": \"background\"},
 \"responses\": {\"left\": \"Left\", \"right\": \"Right\", \"cant_tell\": \"Down\"}")
file(WRITE ${H}/screen-radius.json "{\"name\": \"screen-radius\", ${SCREEN_PROTOCOL_REST},
 \"content\": {\"type\": \"grid\"}, \"factors\": {\"edge\": [1]}, \"sides\": {\"left\": 100, \"right\": \"none\"},
 \"display\": {\"width_px\": 1280, \"height_px\": 720, \"scale\": 8}}")
file(WRITE ${H}/screen-streak.json "{\"name\": \"screen-streak\", ${SCREEN_PROTOCOL_REST},
 \"content\": {\"type\": \"ball\", \"exposure_ms\": 1000}, \"factors\": {\"speed_cm_s\": [100]},
 \"sides\": {\"left\": \"fitted\", \"right\": \"none\"}, \"display\": {\"width_px\": 1280, \"height_px\": 720}}")
file(WRITE ${H}/screen-staircase.json "{\"name\": \"screen-staircase\", ${SCREEN_PROTOCOL_REST},
 \"content\": {\"type\": \"grid\"}, \"display\": {\"width_px\": 1280, \"height_px\": 720, \"scale\": 0.5},
 \"blocks\": [{\"name\": \"s\", \"factors\": {\"edge\": [1]}, \"procedure\": {\"type\": \"staircase\",
   \"variable\": \"relative_difference\", \"reference\": 100, \"trials\": 4, \"start\": 1, \"min\": 0, \"max\": 10,
   \"steps\": [1]}}]}")
foreach(case "radius;/sides/left: the left grid would be blurred by 100 photo px, 800 px on the screen (8 screen px per photo px), more than the largest blur drawn (500 px)"
             "streak;/content/exposure_ms: is 1000 ms: the left ball rolling at 100 cm/s would be streaked over"
             "staircase;/blocks/0/procedure/max: at its largest level, 10, a radius of 1100 photo px, 550 px on the screen (0.5 screen px per photo px)")
  list(GET case 0 tag)
  list(GET case 1 text)
  hostile_test(cli_hostile_validate_screen_${tag} 3 "screen-${tag}.json: ${text}" validate ${H}/screen-${tag}.json)
  hostile_test(cli_hostile_run_screen_${tag} 3 "screen-${tag}.json: ${text}"
               run ${H}/screen-${tag}.json --participant P1 --db ${H}/screen-${tag}.sqlite --observer sim)
  set_tests_properties(cli_hostile_validate_screen_${tag} cli_hostile_run_screen_${tag} PROPERTIES
                       FIXTURES_REQUIRED "scene;calib")
endforeach()

# A participant information key given twice: refused naming the key and both values, not the last one kept.
hostile_test(cli_hostile_run_info_given_twice 2 "--info age is given twice ('age=34' and 'age=35')"
             run ${PROJECT_SOURCE_DIR}/protocols/groups-and-info.json --participant P1 --db ${H}/info-twice.sqlite
             --observer sim --info age=34 --info handedness=right --info vision=normal --info age=35)
# A 100,000-digit value is quoted by its first 60 characters and its length, not written out whole (core/typed.h Echo).
string(REPEAT "1" 100000 digits)
string(REPEAT "1" 60 shown)
hostile_test(cli_hostile_observer_weber_100000_digits 2
             "--observer weber must be a number, got '${shown}...' (100000 characters)"
             run ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json --participant P1 --db ${H}/x.sqlite
             --observer sim:weber=${digits})
hostile_test(cli_hostile_radius_100000_digits 2 "--radius-px: must be in [0, 500] px, got '${shown}...' (100000 characters)"
             blur ${D}/small.png --radius-px ${digits} --out ${H}/x.png)

# An overexposed photo (the scene x 1.3: the board's white squares clip) leaves the first and last edges alone: at two
# depths a focus between them and one beyond them fit alike (it gave focus 140 mm for 400, exit 0): refused, exit 4,
# saying which edges were usable and why the others were not.
add_test(NAME cli_hostile_overexposed_make
         COMMAND /usr/bin/python3 -c "import sys, numpy as np; from PIL import Image; a = np.asarray(Image.open(sys.argv[1]).convert('RGB')).astype(float); Image.fromarray(np.clip(a * 1.3, 0, 255).astype(np.uint8)).save(sys.argv[2])"
                 ${T}/scene/scene.png ${H}/overexposed.png)
set_tests_properties(cli_hostile_overexposed_make PROPERTIES FIXTURES_REQUIRED scene FIXTURES_SETUP overexposed)
hostile_test(cli_hostile_calibrate_two_depths 4
             "overexposed.png: only 2 of 11 edges have a usable section (edge 1 and 11); the others' sections are flagged saturated"
             calibrate ${H}/overexposed.png --camera ${T}/scene/camera.json --out ${H}/calib-two-depths.json)
set_tests_properties(cli_hostile_calibrate_two_depths PROPERTIES FIXTURES_REQUIRED "scene;overexposed")
# A lens model whose aperture is far from the camera's (here camera.json says f/1.4 of a photo taken at f/5.6; a board
# with its edges covered gave an aperture of 0 and focus 21 mm): written, with a warning naming both apertures.
add_test(NAME cli_calibrate_aperture_far_from_nominal
         COMMAND ${BLURCUE_EXPECT} "warning: .*scene.png: the fitted aperture [0-9.]+ mm is 0.2[0-9] x the camera's \\(15.000 mm, f/1.4\\)" sh -c "/usr/bin/python3 -c \"import json, sys; c = json.load(open(sys.argv[1])); c['f_number'] = 1.4; json.dump(c, open(sys.argv[2], 'w'))\" ${T}/scene/camera.json ${H}/camera-f1.4.json && $<TARGET_FILE:blurcue> calibrate ${T}/scene/scene.png --camera ${H}/camera-f1.4.json --out ${H}/calib-f1.4.json --quiet")
set_tests_properties(cli_calibrate_aperture_far_from_nominal PROPERTIES FIXTURES_REQUIRED scene)

# live --measure-sections N feeds the lens model alone: with --blur none, a fixed radius or estimated (eq. 3.7 from the
# given reference edge) the sections were measured every frame (live.csv said so, lens_sections counted them) and
# nothing drawn used them. Refused before any file is
# read, naming both options.
foreach(pair "none;none" "radius;3" "estimated;estimated")
  list(GET pair 0 tag)
  list(GET pair 1 value)
  hostile_test(cli_hostile_live_measure_sections_blur_${tag} 2
               "--measure-sections 5: feeds the lens model, which --blur ${value} does not draw with"
               live ${T}/scene/scene.png --camera ${T}/scene/camera.json --calib ${T}/calib.json --ball 87.5,125
               --measure-sections 5 --blur ${value} --log ${H}/live-measure-${tag})
  set_tests_properties(cli_hostile_live_measure_sections_blur_${tag} PROPERTIES FIXTURES_REQUIRED "scene;calib")
endforeach()
# bench live --quick runs N = 0, 4, 77 on at most 12 frames: --sections, or --frames over 12, beside it was ignored
# (the run took minutes and its CSV said nothing of it). Refused before anything is rendered.
hostile_test(cli_hostile_bench_live_quick_sections 2 "--sections: --quick runs N = 0, 4, 77 and would ignore it"
             bench live --quick --sections 1,2 --out ${H}/bench-live.csv)
hostile_test(cli_hostile_bench_live_quick_frames 2 "--frames 20: --quick runs at most 12 frames and would ignore it"
             bench live --quick --frames 20 --out ${H}/bench-live.csv)
# A value of N given twice ran twice, into the same log folder, and wrote two rows for it.
hostile_test(cli_hostile_bench_live_sections_twice 2 "--sections: 4 is given twice; give each value of N once"
             bench live --sections 0,4,4 --out ${H}/bench-live.csv)
# bench live and bench track run the blurcue beside them: --out naming that executable replaced it with the CSV.
foreach(bench live track)
  hostile_test(cli_hostile_bench_${bench}_out_is_blurcue 2
               "is also the input the blurcue it runs $<TARGET_FILE:blurcue>; an output may not replace an input"
               bench ${bench} --quick --out $<TARGET_FILE:blurcue>)
endforeach()
# A TMPDIR that is a file or no folder at all: bench live (and bench track) ended in std::filesystem's own words as an
# internal error (exit 10); now one line naming TMPDIR, exit 3, before anything is rendered. Their scratch folder is
# made new (mkdtemp): bench live used to remove whatever TMPDIR/blurcue-bench-live-PID held first.
foreach(pair "file;${D}/small.png;Not a directory" "missing;${H}/no-such-tmpdir;No such file or directory")
  list(GET pair 0 tag)
  list(GET pair 1 value)
  list(GET pair 2 why)
  hostile_test(cli_hostile_bench_live_tmpdir_${tag} 3 "TMPDIR ${value}: ${why}; the bench writes its take there"
               bench live --quick --out ${H}/bench-live.csv)
  set_tests_properties(cli_hostile_bench_live_tmpdir_${tag} PROPERTIES ENVIRONMENT "TMPDIR=${value}")
endforeach()
# live --log DIR replaces DIR whole when it holds live's files only; frame-NNNN.png counts as one (--save-frame), so a
# folder of such images alone (ar --frames, a take's frames) was replaced and its images deleted. A log live wrote
# always holds live.csv: without it, refused before anything is read (a usage error, exit 2, as for any folder live
# may not replace: docs/live.md).
add_test(NAME cli_hostile_live_log_of_frames_make
         COMMAND ${CMAKE_COMMAND} -E copy ${D}/small.png ${H}/live-frames-only/frame-0000.png)
set_tests_properties(cli_hostile_live_log_of_frames_make PROPERTIES FIXTURES_SETUP live_frames_only)
hostile_test(cli_hostile_live_log_of_frames 2 "--log ${H}/live-frames-only: holds no live.csv: not a log live wrote"
             live ${T}/scene/scene.png --camera ${T}/scene/camera.json --calib ${T}/calib.json --ball 87.5,125
             --log ${H}/live-frames-only)
set_tests_properties(cli_hostile_live_log_of_frames PROPERTIES FIXTURES_REQUIRED "scene;calib;live_frames_only")
# synth-scene --out DIR replaces DIR whole when it holds its four file names only: a folder of one's own camera.json
# (or a photo named scene.png) alone was replaced, the file gone. A scene it wrote always holds truth.json.
add_test(NAME cli_hostile_synth_scene_own_camera_make
         COMMAND ${CMAKE_COMMAND} -E copy ${T}/scene/camera.json ${H}/own-camera/camera.json)
set_tests_properties(cli_hostile_synth_scene_own_camera_make PROPERTIES FIXTURES_REQUIRED scene
                     FIXTURES_SETUP own_camera)
hostile_test(cli_hostile_synth_scene_own_camera 3 "--out ${H}/own-camera: holds no truth.json: not a scene synth-scene wrote"
             synth-scene --out ${H}/own-camera --width 300)
set_tests_properties(cli_hostile_synth_scene_own_camera PROPERTIES FIXTURES_REQUIRED own_camera)
# The same for synth-take --out (a take it wrote always holds take.json).
hostile_test(cli_hostile_synth_take_own_camera 3 "--out ${H}/own-camera: holds no take.json: not a take synth-take wrote"
             synth-take --out ${H}/own-camera --frames 2)
set_tests_properties(cli_hostile_synth_take_own_camera PROPERTIES FIXTURES_REQUIRED own_camera)

# --- guard: small mends of the outputs audit (tests/outputs_own_test.sh holds the rest, over the CLI tests' scene).
# A repeated distance wrote one photo and said "wrote 1 photos"; two distances %g prints alike wrote one file.
hostile_test(cli_hostile_synth_pictures_repeated_distance 2 "--distances-m 1 is given twice"
             synth-pictures --camera ${D}/thesis-camera.json --distances-m 1 1 --out ${H}/pictures-twice)
hostile_test(cli_hostile_synth_pictures_distances_one_name 2 "distances 1 and 1.0000001 m both name face-1m.png"
             synth-pictures --camera ${D}/thesis-camera.json --distances-m 1 1.0000001 --out ${H}/pictures-twice)
# A display no participant has (render wrote a 1 x 1 image): the display profile's width range.
hostile_test(cli_hostile_render_display_width_1 2 "--display-width: must be 0 (the photo's own width) or a display's width, 320 to 16384 px"
             render --background ${D}/small.png --object picture --display-width 1 --out ${H}/tiny.png)
# names: every name on the command line is checked (the charter: a name the code would ignore is an error with a
# did-you-mean). An unknown option said only "The following arguments were not expected: sharpen --post-filtr", and
# a slip of a required option's name ("--boadr") only that the option was missing, or that its value was no file.
hostile_test(cli_names_unknown_option 2 "synth-scene: unknown option --post-filtr (did you mean --post-filter?)"
             synth-scene --out ${H}/names-scene --post-filtr sharpen)
hostile_test(cli_names_unknown_flag 2 "calibrate: unknown option --no-phase-chek (did you mean --no-phase-check?)"
             calibrate ${D}/small.png --camera ${D}/thesis-camera.json --no-phase-chek)
hostile_test(cli_names_unknown_option_before_required 2 "calibrate: unknown option --boadr (did you mean --board?)"
             calibrate --boadr 10x7 ${D}/small.png)
hostile_test(cli_names_unknown_option_with_value 2 "render: unknown option --backgrund (did you mean --background?)"
             render --calib ${D}/thesis-camera.json --backgrund=${D}/small.png --out ${H}/x.png)
hostile_test(cli_names_unknown_option_far 2
             "synth-scene: unknown option --frobnicate; 'blurcue synth-scene --help' lists the options"
             synth-scene --out ${H}/names-scene --frobnicate)
# A value that looks like an option is the option's value, as CLI11 reads it: the slip after it is still found.
hostile_test(cli_names_unknown_after_negative_value 2 "synth-take: unknown option --to-lateral (did you mean --to-lateral-mm?)"
             synth-take --out ${H}/names-take --from-lateral-mm -15 --to-lateral 15)
hostile_test(cli_names_unknown_subcommand 2 "bench: unknown command 'rendr' (did you mean render?)" bench rendr)
# Word options (every command's, declared through cli::OneOf): the value's nearest allowed word, a case slip first.
hostile_test(cli_names_enum_value 2 "--psf: must be one of disc, gaussian, got 'disk' (did you mean disc?)"
             synth-scene --out ${H}/names-scene --psf disk)
hostile_test(cli_names_enum_case 2 "--preset: must be one of quarter, thesis, got 'Quarter' (did you mean quarter?)"
             synth-scene --out ${H}/names-scene --preset Quarter)
hostile_test(cli_names_enum_far 2 "--backend: must be one of gl, cpu, got 'vulkan'"
             blur ${D}/small.png --radius-px 2 --backend vulkan --out ${H}/x.png)
# camera.json: a misspelt key is named with its did-you-mean ("/f_number: is required but missing" named neither).
file(WRITE ${H}/camera-misspelt.json
     "{\"focal_length_mm\": 21, \"f_numbr\": 5.6, ${CAMERA_REST}, \"image_width_px\": 1148}")
hostile_test(cli_names_camera_key 3 "camera-misspelt.json: /f_numbr: is not a camera field (did you mean f_number?)"
             estimate --camera ${H}/camera-misspelt.json ${ESTIMATE_ARGS})
# init --photo of a PNG (no EXIF) said to give --focal-length-mm, --f-number and --sensor-mm, which init does not take.
hostile_test(cli_names_init_photo_without_exif 3
             "(EXIF is read from JPEG files); give init --camera FILE, a camera.json made by 'blurcue camera"
             init ${H}/names-study --photo ${D}/small.png)
# calibrate --board 10x7 on a 7x10 board: found all the same (the grid turned a quarter), exit 0 and all 8 edges at
# one depth (440.8 mm). Refused, naming the other reading; --board-turned takes it (turned_pose_85).
hostile_test(cli_names_board_transposed 2
             "scene.png: board 10x7 found with its edges running into depth (90.0 deg from across the view: its 8 edges within 0.0 mm of one depth"
             calibrate ${T}/scene/scene.png --camera ${T}/scene/camera.json --board 10x7 --out ${H}/names-calib.json)
set_tests_properties(cli_names_board_transposed PROPERTIES FIXTURES_REQUIRED scene)
# calibrate --truth of another scene printed its pose as the calibration's error (221 mm / 89 deg): refused, before
# anything is written - another camera or board at once, another pose after detection.
add_test(NAME cli_names_other_scene COMMAND ${BC} synth-scene --out ${H}/names-other --seed 3 --yaw-deg 25 --quiet)
set_tests_properties(cli_names_other_scene PROPERTIES FIXTURES_SETUP names_other)
hostile_test(cli_names_truth_other_pose 3 "its pose puts the board's corners"
             calibrate ${T}/scene/scene.png --camera ${T}/scene/camera.json --truth ${H}/names-other/truth.json
             --out ${H}/names-calib.json)
set_tests_properties(cli_names_truth_other_pose PROPERTIES FIXTURES_REQUIRED "scene;names_other")
add_test(NAME cli_names_small_scene COMMAND ${BC} synth-scene --out ${H}/names-small --seed 3 --width 600 --quiet)
set_tests_properties(cli_names_small_scene PROPERTIES FIXTURES_SETUP names_small)
hostile_test(cli_names_truth_other_camera 3 "names-small/truth.json: /camera/image_width_px is 600, "
             calibrate ${T}/scene/scene.png --camera ${T}/scene/camera.json --truth ${H}/names-small/truth.json
             --out ${H}/names-calib.json)
set_tests_properties(cli_names_truth_other_camera PROPERTIES FIXTURES_REQUIRED "scene;names_small")
hostile_test(cli_names_truth_other_board 3 "/board is 7x10 of 25 mm, not the --board 10x7 of 25 mm given: the truth of another scene"
             calibrate ${T}/scene/scene.png --camera ${T}/scene/camera.json --board 10x7 --truth ${T}/scene/truth.json
             --out ${H}/names-calib.json)
set_tests_properties(cli_names_truth_other_board PROPERTIES FIXTURES_REQUIRED scene)

# --- mends: refusals and warnings around calibrate, render and run.
# measured / measured_section where the nearest edge's sections are all flagged (here edge 5's, phase_limited, as a
# photo filtered after sampling leaves an edge along the pixel rows): exit 4 and a line naming neither calib.json nor
# its field. Now exit 3 naming the file, the sections' "ok" and their flags - through render and through a protocol.
add_test(NAME cli_hostile_measured_flagged_make
         COMMAND /usr/bin/python3 -c "import json, sys; c = json.load(open(sys.argv[1]))\nfor s in c['edges'][4]['sections']: s['ok'] = False; s['flags'] = ['phase_limited']\nc['edges'][4]['usable_sections'] = 0; json.dump(c, open(sys.argv[2], 'w'), indent=1)\np = json.load(open(sys.argv[3])); p['scene'] = {'background': sys.argv[5], 'calib': sys.argv[2], 'show': 'background'}; json.dump(p, open(sys.argv[4], 'w'), indent=1)"
                 ${T}/calib.json ${H}/calib-e5.json ${PROJECT_SOURCE_DIR}/protocols/test1-static-grids.json
                 ${H}/protocol-e5.json ${T}/scene/scene.png)
set_tests_properties(cli_hostile_measured_flagged_make PROPERTIES FIXTURES_REQUIRED "scene;calib"
                     FIXTURES_SETUP measured_flagged)
hostile_test(cli_hostile_render_measured_flagged_edge 3
             "calib-e5.json: /edges/4: edge 5 (the nearest) has no usable measured section: "
             render --calib ${H}/calib-e5.json --background ${T}/scene/scene.png --blur measured --at-edge 5 --out ${H}/x.png)
hostile_test(cli_hostile_render_measured_section_flagged 3
             "calib-e5.json: /edges/4/sections/3/ok: is false (flagged phase_limited): edge 5 section 4 (the nearest) is not usable"
             render --calib ${H}/calib-e5.json --background ${T}/scene/scene.png --blur measured_section --at-edge 5
             --out ${H}/x.png)
hostile_test(cli_hostile_validate_measured_flagged_edge 3
             "calib-e5.json: /edges/4: edge 5 (the nearest) has no usable measured section: "
             validate ${H}/protocol-e5.json)
hostile_test(cli_hostile_run_measured_flagged_edge 3
             "calib-e5.json: /edges/4: edge 5 (the nearest) has no usable measured section: "
             run ${H}/protocol-e5.json --participant P1 --db ${H}/measured-flagged.sqlite --observer sim)
set_tests_properties(cli_hostile_render_measured_flagged_edge cli_hostile_render_measured_section_flagged
                     cli_hostile_validate_measured_flagged_edge cli_hostile_run_measured_flagged_edge PROPERTIES
                     FIXTURES_REQUIRED "scene;calib;measured_flagged")
# calibrate with a camera.json whose focal length is far off the photo's (50 mm for 21): the pose fits its corners to
# 8.6 px, the reference edge's phase_limited readings gave r = 109695 px and eq. 3.7 110000 px, exit 0. Refused,
# naming camera.json's focal_length_mm: no section of a board whose squares span 61 px can show such a blur.
set(CAMERA_SENSOR "\"sensor_width_mm\": 23.4, \"sensor_height_mm\": 15.6, \"image_width_px\": 1148, \"image_height_px\": 764")
file(WRITE ${H}/camera-f50.json "{\"focal_length_mm\": 50, \"f_number\": 5.6, ${CAMERA_SENSOR}}")
hostile_test(cli_hostile_calibrate_focal_length_far 3
             "camera-f50.json: /focal_length_mm: is 50 mm, and with it the board's corners fit the pose only to 8.59 px"
             calibrate ${T}/scene/scene.png --camera ${H}/camera-f50.json --reference-edge 5 --out ${H}/calib-f50.json)
set_tests_properties(cli_hostile_calibrate_focal_length_far PROPERTIES FIXTURES_REQUIRED scene)
# A JPEG of quality 3 of the scene: every section off, chi-square per point 484550, exit 0. Refused, saying why.
add_test(NAME cli_hostile_jpeg_q3_make
         COMMAND /usr/bin/python3 -c "import sys; from PIL import Image; Image.open(sys.argv[1]).convert('RGB').save(sys.argv[2], quality=3)"
                 ${T}/scene/scene.png ${H}/scene-q3.jpg)
set_tests_properties(cli_hostile_jpeg_q3_make PROPERTIES FIXTURES_REQUIRED scene FIXTURES_SETUP jpeg_q3)
hostile_test(cli_hostile_calibrate_jpeg_q3 3
             "scene-q3.jpg: the board's edges do not fit a blurred edge: the best of the PSF families leaves residuals"
             calibrate ${H}/scene-q3.jpg --camera ${T}/scene/camera.json --out ${H}/calib-q3.json)
set_tests_properties(cli_hostile_calibrate_jpeg_q3 PROPERTIES FIXTURES_REQUIRED "scene;jpeg_q3")
# track --board 10x7 on a 7x10 board: tracked with exit 0 (calibrate refuses it). Refused alike, naming the frame.
add_test(NAME cli_hostile_track_transposed_make COMMAND ${CMAKE_COMMAND} -E copy ${T}/scene/scene.png ${H}/seq/frame-0000.png)
set_tests_properties(cli_hostile_track_transposed_make PROPERTIES FIXTURES_REQUIRED scene FIXTURES_SETUP one_frame)
hostile_test(cli_hostile_track_board_transposed 2
             "frame-%04d.png: frame 0: board 10x7 found with its edges running into depth (90.0 deg from across the view"
             track ${H}/seq/frame-%04d.png --camera ${T}/scene/camera.json --board 10x7 --out ${H}/track-transposed --quiet)
set_tests_properties(cli_hostile_track_board_transposed PROPERTIES FIXTURES_REQUIRED "scene;one_frame")
# run refusing --capture (a folder of one's own) on an existing record left its -wal and -shm beside it.
add_test(NAME cli_hostile_run_capture_refused_no_sidecars
         COMMAND ${BLURCUE_EXPECT} "ok: refused, no -wal or -shm"
                 sh -c "rm -rf ${H}/sidecars && mkdir -p ${H}/sidecars/shots && echo mine > ${H}/sidecars/shots/notes.txt && $<TARGET_FILE:blurcue> run ${T}/protocols/test1-static-grids.json --participant P1 --db ${H}/sidecars/r.sqlite --observer sim --stop-after 1 > /dev/null 2>&1; $<TARGET_FILE:blurcue> run ${T}/protocols/test1-static-grids.json --participant P1 --db ${H}/sidecars/r.sqlite --observer sim --resume --capture ${H}/sidecars/shots 2> ${H}/sidecars/err; test $? = 3 && grep -q 'holds .notes.txt., which is not a capture' ${H}/sidecars/err && test -s ${H}/sidecars/r.sqlite && test ! -e ${H}/sidecars/r.sqlite-wal && test ! -e ${H}/sidecars/r.sqlite-shm && echo 'ok: refused, no -wal or -shm'")
set_tests_properties(cli_hostile_run_capture_refused_no_sidecars PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS gl)
# Every edge blurred 2 px or more under a strong sharpening after sampling (focus at 5 m; masks of amount 1 over 2 px,
# and of 0.7 over 0.6 px): nothing chose a PSF family there, and the first was written with exit 0, every section
# 2.5 px off. Now the families are read on the wide sections too: refused where the mask moves their readings by more
# than 3 % (here 5.7 %, a lower bound), kept and said where it moves them little (1.3 %; those read 1.6 % high).
foreach(mask "strong;2;1" "mild;0.6;0.7")
  list(GET mask 0 tag)
  list(GET mask 1 sigma)
  list(GET mask 2 amount)
  add_test(NAME cli_hostile_wide_sharpened_${tag}_make
           COMMAND $<TARGET_FILE:blurcue> synth-scene --out ${H}/wide-sharpened-${tag} --seed 20 --post-filter sharpen
                   --post-sigma-px ${sigma} --post-amount ${amount} --focus-mm 5000 --noise 0.004)
  set_tests_properties(cli_hostile_wide_sharpened_${tag}_make PROPERTIES FIXTURES_SETUP wide_sharpened_${tag})
endforeach()
hostile_test(cli_hostile_calibrate_wide_sharpened 3
             "scene.png: the board's edges fit the optics then sharpening (unsharp mask of amount 0.70, std 1.00 px) better than the optics alone (chi-square 313 against 488 over 12 sections, in units of their noise), which moves their readings by 5.7 % (median; at least)"
             calibrate ${H}/wide-sharpened-strong/scene.png --camera ${H}/wide-sharpened-strong/camera.json
             --out ${H}/wide-sharpened-strong-calib.json)
set_tests_properties(cli_hostile_calibrate_wide_sharpened PROPERTIES FIXTURES_REQUIRED wide_sharpened_strong)
add_test(NAME cli_calibrate_wide_sharpened_mild_kept
         COMMAND ${BLURCUE_EXPECT} "phase check: no usable section has blur under 2 px; the optics then sharpening \\(unsharp mask of amount 0\\.70, std 0\\.60 px\\) fits 12 of the wider sections better than the optics alone, moving their readings by 1\\.[0-9] % \\(median\\)"
                 $<TARGET_FILE:blurcue> calibrate ${H}/wide-sharpened-mild/scene.png
                 --camera ${H}/wide-sharpened-mild/camera.json --out ${H}/wide-sharpened-mild-calib.json)
set_tests_properties(cli_calibrate_wide_sharpened_mild_kept PROPERTIES FIXTURES_REQUIRED wide_sharpened_mild)
# A board photographed straight down (every edge at one depth) fitted an aperture of 2458 mm and was written; every
# later command refused the file. What calibrate writes is read back through the readers' code first.
add_test(NAME cli_hostile_face_on_make
         COMMAND $<TARGET_FILE:blurcue> synth-scene --out ${H}/face-on --seed 14 --tilt-deg 90)
set_tests_properties(cli_hostile_face_on_make PROPERTIES FIXTURES_SETUP face_on)
hostile_test(cli_hostile_calibrate_face_on 3
             "scene.png: the calibration would not be one blurcue can use (/model/aperture_mm: must be in [0, 1000] mm, got"
             calibrate ${H}/face-on/scene.png --camera ${H}/face-on/camera.json --out ${H}/face-on-calib.json)
set_tests_properties(cli_hostile_calibrate_face_on PROPERTIES FIXTURES_REQUIRED face_on)
# A scene with no blur at all on an unfiltered photo: the model's "not determined" line blamed a sharpening.
add_test(NAME cli_hostile_no_blur_make
         COMMAND $<TARGET_FILE:blurcue> synth-scene --out ${H}/no-blur --seed 9 --fixed-r-px 0)
set_tests_properties(cli_hostile_no_blur_make PROPERTIES FIXTURES_SETUP no_blur)
add_test(NAME cli_calibrate_no_blur_model_says_why
         COMMAND ${BLURCUE_EXPECT} "\nmodel: the model's blur is not determined within 5 % at depths [0-9]+-[0-9]+ mm: [0-9]+ sections at [0-9]+-[0-9]+ mm read 0 px, sharper than their profiles can tell apart"
                 $<TARGET_FILE:blurcue> calibrate ${H}/no-blur/scene.png --camera ${H}/no-blur/camera.json
                 --out ${H}/no-blur-calib.json)
set_tests_properties(cli_calibrate_no_blur_model_says_why PROPERTIES FIXTURES_REQUIRED no_blur)
# init runs the binary it is (a copy under another name ran <its folder>/blurcue, exit 127).
add_test(NAME cli_init_from_a_renamed_copy
         COMMAND ${BLURCUE_EXPECT} "init: [^\n]*init-renamed is ready"
                 bash -c "cp \"$1\" \"$2/bc-renamed\" && rm -rf \"$2/init-renamed\" && \"$2/bc-renamed\" init \"$2/init-renamed\""
                 _ $<TARGET_FILE:blurcue> ${H})
