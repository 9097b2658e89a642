# End-to-end tests of blurcue run / preview on real SQLite files, over the CLI tests' scene (fixtures scene, calib).
set(BC $<TARGET_FILE:blurcue>)
set(T ${PROJECT_BINARY_DIR}/cli-test)
add_test(NAME session_protocols
         COMMAND ${CMAKE_COMMAND} -DSRC=${PROJECT_SOURCE_DIR} -DOUT=${T} -P ${PROJECT_SOURCE_DIR}/tests/copy_protocols.cmake)
# The depth-matching protocol's real photos, one per distance, by the thin lens.
add_test(NAME session_pictures
         COMMAND ${BC} synth-pictures --camera ${T}/scene/camera.json
                 --protocol ${PROJECT_SOURCE_DIR}/protocols/pre-research-depth-matching.json --out ${T}/pictures)
set_tests_properties(session_pictures PROPERTIES FIXTURES_REQUIRED scene FIXTURES_SETUP session_pictures
                     PASS_REGULAR_EXPRESSION "wrote 27 photos")
set_tests_properties(session_protocols PROPERTIES FIXTURES_SETUP session_protocols)
foreach(case complete same_seed resume kill9 second_writer window window_adjust recover merge resume_guards stranded
             stale_lock readonly)
  add_test(NAME session_${case} COMMAND bash ${PROJECT_SOURCE_DIR}/tests/session_test.sh ${case} ${BC} ${T})
  set_tests_properties(session_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols;session_pictures"
                       LABELS "gl;session"
                       PASS_REGULAR_EXPRESSION "^ok:|\nok:")
endforeach()
set_tests_properties(session_window session_window_adjust PROPERTIES LABELS "gl;session;window")

add_test(NAME session_preview
         COMMAND ${BC} preview ${T}/protocols/test1-static-grids.json --out ${T}/preview-test1.png)
set_tests_properties(session_preview PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS gl
                     PASS_REGULAR_EXPRESSION "11 distinct stimuli of 13 trials")
# Bad input: exit code and one line naming what is wrong (tests/expect_failure.cmake). NAME CODE TEXT ARGS...
function(add_run_failure_test name code text)
  add_test(NAME ${name}
           COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=${ARGN}" -DEXPECT_CODE=${code} "-DEXPECT_TEXT=${text}"
                   -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
  set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols")
endfunction()
add_run_failure_test(session_run_broken_protocol 3 "broken-protocol.json: /"
                     run ${PROJECT_SOURCE_DIR}/tests/data/broken-protocol.json --participant P1 --db ${T}/broken.sqlite
                     --observer sim)
add_run_failure_test(session_run_bad_observer 2 "--observer: unknown parameter 'jdn'"
                     run ${T}/protocols/test1-static-grids.json --participant P1 --db ${T}/bad-observer.sqlite
                     --observer sim:jdn=1)
add_run_failure_test(session_run_negative_seed 2
                     "--seed: must be a whole number from 0 to 18446744073709551615, got '-3'"
                     run ${T}/protocols/test1-static-grids.json --participant P1 --db ${T}/seed.sqlite --observer sim
                     --seed -3)
# A person needs a window: without a display, one line says so (and what to do) before anything is recorded.
add_test(NAME session_run_person_without_display
         COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY ${CMAKE_COMMAND} -DCMD=${BC}
                 "-DARGS=run;${T}/protocols/test1-static-grids.json;--participant;P1;--db;${T}/no-display.sqlite"
                 -DEXPECT_CODE=10 "-DEXPECT_TEXT=GLFW: cannot open a window: "
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(session_run_person_without_display PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols")

# blurcue display check in a window (its own Xvfb): geometry, resolution check, honest timing without vsync.
add_test(NAME display_check COMMAND bash ${PROJECT_SOURCE_DIR}/tests/display_test.sh ${BC} ${T})
set_tests_properties(display_check PROPERTIES LABELS "gl;window" PASS_REGULAR_EXPRESSION "^ok:|\nok:")
