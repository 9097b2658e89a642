# What a kill -9 of merge, export and report leaves behind (tests/outputs_kill_test.sh): the old output or the whole
# new one, no surviving analysis process, and leftovers that the next run removes. Over the CLI tests' scene.
foreach(case merge export report)
  add_test(NAME outputs_kill_${case}
           COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/outputs_kill_test.sh ${case} $<TARGET_FILE:blurcue>
                   ${PROJECT_BINARY_DIR}/cli-test)
  set_tests_properties(outputs_kill_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                       LABELS "gl;outputs" TIMEOUT 120)
endforeach()

# An output that cannot be written is exit 3 naming it (it was exit 10 when std::filesystem::rename threw): here
# calib.json aimed at an existing folder, which is left as it was.
add_test(NAME outputs_json_onto_a_folder
         COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue>
                 "-DARGS=calibrate;${PROJECT_BINARY_DIR}/cli-test/scene/scene.png;--camera;${PROJECT_BINARY_DIR}/cli-test/scene/camera.json;--out;${PROJECT_BINARY_DIR}/cli-test/scene"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=cli-test/scene: is a folder, not a file; not replaced"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(outputs_json_onto_a_folder PROPERTIES FIXTURES_REQUIRED scene)

# Installed into a temporary prefix and moved: the binary finds what it ships beside itself (tests/install_test.sh).
add_test(NAME install_relocatable
         COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/install_test.sh ${PROJECT_BINARY_DIR} ${PROJECT_BINARY_DIR}/install-test)
set_tests_properties(install_relocatable PROPERTIES LABELS gl)

# blurcue init from an installed, moved prefix: shipped examples as study folders that validate and run.
add_test(NAME init_from_prefix
         COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/init_test.sh ${PROJECT_BINARY_DIR} ${PROJECT_BINARY_DIR}/init-test)
set_tests_properties(init_from_prefix PROPERTIES LABELS gl)
# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(init_from_prefix 124 outputs_kill_export 21 outputs_kill_report 17)

# Issue 39, nothing an experimenter owns is destroyed: what an adversary tried against ar, track, init, calibrate and
# camera (an output that is an input, a record as a CSV, a FIFO input, an output of another kind, no limits) is
# refused before any work, in one line, and leaves every file as it was (tests/outputs_guard_test.sh).
add_test(NAME outputs_guard_cli
         COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/outputs_guard_test.sh $<TARGET_FILE:blurcue> ${PROJECT_BINARY_DIR})
set_tests_properties(outputs_guard_cli PROPERTIES LABELS "gl;outputs" TIMEOUT 120)
# 20 kill -9s of track, ar and init at random points (seeded, the seed printed) while they write over an earlier
# output: always the earlier output or the whole new one, and a rerun that succeeds and removes the leftovers
# (tests/outputs_take_kill_test.sh).
foreach(case track ar init)
  add_test(NAME outputs_kill_${case}
           COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/outputs_take_kill_test.sh ${case} $<TARGET_FILE:blurcue>
                   ${PROJECT_BINARY_DIR})
  set_tests_properties(outputs_kill_${case} PROPERTIES LABELS "gl;outputs" TIMEOUT 150)
endforeach()
set_test_costs(outputs_kill_init 31 outputs_kill_ar 25 outputs_kill_track 15 outputs_guard_cli 8)

# What the adversary of issue 39 found, each mended (tests/adversary39_check.py): an edited record's dangling row and
# protocol text (exit 10 before), preview and render over their own inputs, synth-take over a longer take.
add_test(NAME outputs_adversary39
         COMMAND ${BLURCUE_EXPECT} "(^|\n)ok: " /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/adversary39_check.py
                 $<TARGET_FILE:blurcue> ${PROJECT_BINARY_DIR}/cli-test)
set_tests_properties(outputs_adversary39 PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                     LABELS "gl;outputs")

# An output replaces only what its own command wrote (tests/outputs_own_test.sh): a protocol at animate --log,
# calibrate --out, camera --out or bench --out, a protocol named .png at an image output, one's own face.png, real
# photos, frames, calib-NNNN.json, plan.csv or trials.csv in make-stimuli's, synth-pictures', animate's, track's,
# plan's or export's folder - each was replaced, exit 0 - is refused in one line, exit 3, every file left as it was;
# each command's own outputs are replaced on a rerun. With it the small mends of the same audit (validate's field
# and one line, synth-pictures' repeated distance, render's display width).
add_test(NAME outputs_own_files
         COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/outputs_own_test.sh $<TARGET_FILE:blurcue> ${PROJECT_BINARY_DIR})
set_tests_properties(outputs_own_files PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                     LABELS "gl;outputs" TIMEOUT 300)
set_test_costs(outputs_own_files 38)  # started first on a fresh clone (seconds in one ctest -j2 run)
