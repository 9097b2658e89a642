# End-to-end tests of blurcue run / preview on real SQLite files, over the CLI tests' scene (fixtures scene, calib).
set(BC $<TARGET_FILE:blurcue>)
set(T ${PROJECT_BINARY_DIR}/cli-test)
add_test(NAME session_protocols
         COMMAND ${CMAKE_COMMAND} -DSRC=${PROJECT_SOURCE_DIR} -DOUT=${T} -P ${PROJECT_SOURCE_DIR}/tests/copy_protocols.cmake)
# The depth-matching protocol's real photos, one per distance, by the thin lens.
add_test(NAME session_pictures
         COMMAND ${BLURCUE_EXPECT} "wrote 27 photos" ${BC} synth-pictures --camera ${T}/scene/camera.json
                 --protocol ${PROJECT_SOURCE_DIR}/protocols/pre-research-depth-matching.json --out ${T}/pictures)
set_tests_properties(session_pictures PROPERTIES FIXTURES_REQUIRED scene FIXTURES_SETUP session_pictures)
set_tests_properties(session_protocols PROPERTIES FIXTURES_SETUP session_protocols)
# Each script holds the cases of one concern: the record (session_test.sh), what the design records and reports
# (session_design_test.sh), what the screen shows (session_display_test.sh); session_lib.sh is their shared part.
set(SESSION_CASES_session_test complete same_seed resume kill9 second_writer recover merge merge_live_writer
    merge_killed_session resume_guards stranded stale_lock readonly resume_observer resume_display groups_concurrent
    resume_exact schema1)
set(SESSION_CASES_session_design_test adaptive groups_info codebook report_any_study report_aborted practice_criterion
    level_names odd_names collided_names)
set(SESSION_CASES_session_display_test window window_adjust depth_arcmin frames_shown two_intervals deadline layouts
    window_after_motion visibility depth_capture)
foreach(script session_test session_design_test session_display_test)
  foreach(case ${SESSION_CASES_${script}})
    add_test(NAME session_${case} COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/${script}.sh ${case} ${BC} ${T})
    set_tests_properties(session_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols;session_pictures"
                         LABELS "gl;session")
  endforeach()
endforeach()
set_tests_properties(session_window session_window_adjust session_window_after_motion PROPERTIES LABELS "gl;session;window")
# Sessions numbered per participant, protocol versions kept apart (tests/session_numbers_test.sh).
foreach(case again protocol_version conditions_version again_group balanced_counts merge_people)
  add_test(NAME session_numbers_${case} COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/session_numbers_test.sh ${case} ${BC} ${T})
  set_tests_properties(session_numbers_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                       LABELS "gl;session")
endforeach()
# The report analyses the design the record declares (tests/report_design_test.sh): a QUEST+ per depth per depth,
# between-subject groups compared across participants, unfinished and repeated sessions apart; two within factors
# crossed with an empty crossing, unbalanced cells and level names holding commas, quotes, unicode and HTML.
foreach(case quest_per_depth groups sessions mixed_blocks crossed_hostile)
  add_test(NAME report_design_${case} COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/report_design_test.sh ${case} ${BC} ${T})
  set_tests_properties(report_design_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                       LABELS "gl;session")
endforeach()

add_test(NAME session_preview
         COMMAND ${BLURCUE_EXPECT} "11 distinct stimuli of 13 trials" ${BC} preview ${T}/protocols/test1-static-grids.json --out ${T}/preview-test1.png)
set_tests_properties(session_preview PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS gl)
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
# A --info value of 100,000 characters is quoted by its first 60 and its length (core/typed.h Echo).
string(REPEAT "a" 100000 notes)
string(REPEAT "a" 60 shown)
add_run_failure_test(session_run_info_100000_characters 2
                     "--info notes=${shown}... (100000 characters): must be one line of printable text, at most 200 bytes"
                     run ${T}/protocols/groups-and-info.json --participant P1 --db ${T}/info-long.sqlite --observer sim
                     --info notes=${notes})
# A person needs a window: without a display, one line says so (and what to do) before anything is recorded. No
# display is the station's set-up, a usage error (exit 2), not an internal one.
add_test(NAME session_run_person_without_display
         COMMAND ${CMAKE_COMMAND} -E env --unset=DISPLAY ${CMAKE_COMMAND} -DCMD=${BC}
                 "-DARGS=run;${T}/protocols/test1-static-grids.json;--participant;P1;--db;${T}/no-display.sqlite"
                 -DEXPECT_CODE=2 "-DEXPECT_TEXT=run under xvfb-run); to try the protocol without a participant, run it with --observer sim"
                 -DONE_LINE=1 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(session_run_person_without_display PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols")

# blurcue display check in a window (its own Xvfb): geometry, resolution check, honest timing without vsync.
add_test(NAME display_check COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/display_test.sh ${BC} ${T})
set_tests_properties(display_check PROPERTIES LABELS "gl;window"
                     FIXTURES_REQUIRED "scene;calib;session_protocols")

# Protocols that cannot crash, hang or lie: a seeded generator mutates the shipped protocols (deletions, wrong types,
# extremes, deep nesting, odd strings, bad paths) and runs each through `blurcue validate`, and each one accepted
# through a short simulated `blurcue run`: no signal, no exit 10, no timeout, nothing accepted that then fails, and
# every rejection names the protocol file and the field (a JSON pointer) on each line. The counts are printed; the
# seed is new each run and printed first, with the command that runs the same mutants again.
add_test(NAME session_protocol_fuzz
         COMMAND ${BLURCUE_EXPECT} "fuzz ok: 0 crashes" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/fuzz_protocols.py ${BC} ${T}/protocols ${T}/fuzz
                 --count 250)
set_tests_properties(session_protocol_fuzz PROPERTIES
                     FIXTURES_REQUIRED "scene;calib;session_protocols;session_pictures" LABELS "gl;session;fuzz" TIMEOUT 1200)
# The fuzz's check itself: a stand-in blurcue whose every refusal names no field (or not even the file) fails it.
add_test(NAME session_protocol_fuzz_catches_unnamed
         COMMAND ${BLURCUE_EXPECT} --exit 1 "unnamed_message 8 .*\nfuzz: 8 failures" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/fuzz_protocols.py
                 ${PROJECT_SOURCE_DIR}/tests/fuzz_fake_blurcue.py ${T}/protocols ${T}/fuzz-self --count 8)
set_tests_properties(session_protocol_fuzz_catches_unnamed PROPERTIES FIXTURES_REQUIRED "session_protocols"
                     LABELS "session;fuzz")

# Nothing an experimenter owns is destroyed (tests/record_integrity_test.py): a record whose schema number was edited
# is refused by every command that opens it, the file left as it was; studies whose names share a safe form, or are
# too long for a file name, get exports and report charts of their own.
foreach(case schema_numbers study_names)
  add_test(NAME session_record_${case}
           COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/record_integrity_test.py ${case} ${BC} ${T})
  set_tests_properties(session_record_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                       LABELS "gl;session" TIMEOUT 900)
endforeach()

# validate == run: protocols that used to crash, hang or pass validate and then fail run. Each is refused by both
# commands with the same one line, naming the protocol file and the field. NAME TEXT PROTOCOL-JSON
set(D ${PROJECT_BINARY_DIR}/cli-test-data)
file(WRITE ${D}/not-an-image.png "hello")
function(add_preflight_test name text json)
  file(WRITE ${D}/${name}.json "${json}")
  set(validate_args "validate;${D}/${name}.json")
  set(run_args "run;${D}/${name}.json;--participant;P1;--db;${T}/preflight-${name}.sqlite;--observer;sim")
  foreach(command validate run)
    add_test(NAME session_${command}_${name}
             COMMAND ${CMAKE_COMMAND} -DCMD=${BC} "-DARGS=${${command}_args}"
                     -DEXPECT_CODE=3 "-DEXPECT_TEXT=${name}.json: ${text}"
                     -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
    set_tests_properties(session_${command}_${name} PROPERTIES FIXTURES_REQUIRED "scene;calib")
  endforeach()
endfunction()
set(ball_head "{\"name\": \"t\", \"version\": 1, \"content\": {\"type\": \"ball\"}, \"task\": \"forced_choice\",")
set(ball_scene "\"scene\": {\"background\": \"${T}/scene/scene.png\", \"calib\": \"${T}/calib.json\"}")
set(pattern "{\"speed_cm_s\": 3, \"left\": \"measured\", \"right\": \"none\"}")
add_preflight_test(calib-proc-mem "/scene/calib: not a calibration from blurcue calibrate: /proc/self/mem: cannot read"
                   "${ball_head} \"scene\": {\"background\": \"${T}/scene/scene.png\", \"calib\": \"/proc/self/mem\"}, \"factors\": {\"pattern\": [${pattern}]}}")
add_preflight_test(calib-is-a-camera "/scene/calib: not a calibration from blurcue calibrate: "
                   "${ball_head} \"scene\": {\"background\": \"${T}/scene/scene.png\", \"calib\": \"${T}/scene/camera.json\"}, \"factors\": {\"pattern\": [${pattern}]}}")
add_preflight_test(texture-not-an-image "/content/texture: ${D}/not-an-image.png: not a readable image"
                   "{\"name\": \"t\", \"version\": 1, \"content\": {\"type\": \"ball\", \"texture\": \"not-an-image.png\"}, \"task\": \"forced_choice\", ${ball_scene}, \"factors\": {\"pattern\": [${pattern}]}}")
add_preflight_test(photo-of-another-size "/scene/background: "
                   "${ball_head} \"scene\": {\"background\": \"${T}/pictures/face-0.4m.png\", \"calib\": \"${T}/calib.json\"}, \"factors\": {\"pattern\": [${pattern}]}}")
set_tests_properties(session_validate_photo-of-another-size session_run_photo-of-another-size PROPERTIES
                     FIXTURES_REQUIRED "scene;calib;session_pictures")
add_preflight_test(speed-1e-300 "/factors/pattern/0/speed_cm_s: a speed must be a number in [0.1, 100] cm/s, got 1e-300"
                   "${ball_head} ${ball_scene}, \"factors\": {\"pattern\": [{\"speed_cm_s\": 1e-300, \"left\": \"measured\", \"right\": \"none\"}]}}")
# Edges past the calibrated board (7 x 10 squares here) are named at once with one past any board (edge 12 used to be
# refused only once edge 0 was fixed).
set(cards "{\"name\": \"t\", \"version\": 1, \"content\": {\"type\": \"grid\", \"cells\": 5}, \"task\": \"forced_choice\", ${ball_scene}, \"sides\": {\"left\": \"measured\", \"right\": \"estimated\"}")
add_preflight_test(edges-0-and-12 "/factors/edge/0: an edge must be an integer in [1, 11], the calibrated board's (7 x 10 squares: edges 1-11, sections 1-10 between them), got 0\n${D}/edges-0-and-12.json: /factors/edge/3: an edge must be an integer in [1, 11], the calibrated board's (7 x 10 squares: edges 1-11, sections 1-10 between them), got 12\n(2 problems)"
                   "${cards}, \"factors\": {\"edge\": [0, 5, 8, 12]}}")
# A cut photo and a calibration that does not parse are named with every other problem, not only once the protocol's
# own are mended (validate named the repetitions alone, then the photo): the parser reads each file a protocol
# names as the session will (procedure::PreflightOptions's check_content).
add_preflight_test(cut-photo-with-others "/scene/background: ${PROJECT_SOURCE_DIR}/tests/data/bad-iccp-truncated.png: truncated PNG: chunk 'IDAT' at byte 76 says it holds 457 bytes, past the end of the 92-byte file; the image is cut short\n${D}/cut-photo-with-others.json: /scene/calib: not a calibration from blurcue calibrate: ${T}/scene/camera.json: /format: must be \"blurcue-calib\" (a file written by blurcue calibrate)\n${D}/cut-photo-with-others.json: /repetitions: must be an integer in [1, 10000] repetitions, got 0\n(3 problems)"
                   "${ball_head} \"scene\": {\"background\": \"${PROJECT_SOURCE_DIR}/tests/data/bad-iccp-truncated.png\", \"calib\": \"${T}/scene/camera.json\"}, \"factors\": {\"pattern\": [${pattern}]}, \"repetitions\": 0}")
add_preflight_test(inter-trial-1e308 "/timing/inter_trial_ms: must be a number in [0, 60000] ms, got 1e+308"
                   "${ball_head} ${ball_scene}, \"factors\": {\"pattern\": [${pattern}]}, \"timing\": {\"inter_trial_ms\": 1e308}}")
add_preflight_test(number-1e400 "not valid JSON at line 1, column "
                   "${ball_head} ${ball_scene}, \"factors\": {\"pattern\": [${pattern}]}, \"repetitions\": 1e400}")
string(REPEAT "[" 100000 open)
string(REPEAT "]" 100000 close)
add_preflight_test(nested-100000-deep "not valid JSON: nested deeper than 64 levels at line 1, column "
                   "${ball_head} ${ball_scene}, \"factors\": {\"pattern\": [${pattern}]}, \"instructions\": ${open}${close}}")
set(levels "[1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30]")
add_preflight_test(eight-factors-of-30 "/factors: the session would have 656100000000 trials (30 label_a x 30 label_b x "
                   "${ball_head} ${ball_scene}, \"factors\": {\"pattern\": [${pattern}], \"label_a\": ${levels}, \"label_b\": ${levels}, \"label_c\": ${levels}, \"label_d\": ${levels}, \"label_e\": ${levels}, \"label_f\": ${levels}, \"label_g\": ${levels}, \"label_h\": ${levels}}}")

# A conditions table's cell of Latin-1 bytes or with an escape byte: exit 3 naming the CSV file, its line and column
# (it used to be exit 10, "invalid UTF-8 byte", or an escape written raw into the record).
string(ASCII 255 254 latin1)
string(ASCII 27 escape)
file(WRITE ${D}/latin1-cell.csv "edge,left,right,label\n1,measured,none,caf${latin1}\n")
file(WRITE ${D}/escape-cell.csv "edge,left,right,label\n1,measured,none,ok\n2,measured,none,a${escape}[2Jb\n")
set(grid_head "{\"name\": \"t\", \"version\": 1, \"content\": {\"type\": \"grid\"}, \"task\": \"forced_choice\", ${ball_scene},")
add_preflight_test(latin1-cell "${D}/latin1-cell.csv line 2, column 4 (label): must be printable UTF-8 text"
                   "${grid_head} \"conditions\": \"latin1-cell.csv\"}")
add_preflight_test(escape-cell "${D}/escape-cell.csv line 3, column 4 (label): must be printable UTF-8 text"
                   "${grid_head} \"conditions\": \"escape-cell.csv\"}")
# A quote left open at a line's end: the label "ab" used to be recorded.
file(WRITE ${D}/open-quote.csv "edge,left,right,label\n1,measured,none,ok\n2,measured,none,\"ab\n")
add_preflight_test(open-quote "/conditions: ${D}/open-quote.csv line 3, column 17: a quoted field is not closed"
                   "${grid_head} \"conditions\": \"open-quote.csv\"}")
# A place no layout draws: the single object (and every interval's) stands at the left one's place, so a right_x_mm
# level was recorded on every row though nothing was drawn there.
add_preflight_test(single-right-x-mm
                   "/blocks/0/factors/right_x_mm: the layout single shows every object at the left one's place (move it with left_x_mm): a right_x_mm level would be recorded but not shown, got [100]"
                   "{\"name\": \"t\", \"version\": 1, \"content\": {\"type\": \"grid\"}, \"task\": \"yes_no\", \"layout\": \"single\", ${ball_scene}, \"blocks\": [{\"name\": \"s\", \"factors\": {\"edge\": [3, 7], \"right_x_mm\": [100]}, \"sides\": {\"object\": \"measured\"}}]}")
# A display profile's name is one line of at most 100 characters: a 100,000-character name and one with an escape
# and a newline used to be recorded and printed as they were.
string(REPEAT "x" 100000 long_name)
file(WRITE ${D}/long-name-display.json "{\"name\": \"${long_name}\"}")
file(WRITE ${D}/escape-name-display.json "{\"name\": \"booth\\u001b[2J\\n1\"}")
add_test(NAME session_validate_display_name_long
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC}
                 "-DARGS=validate;${T}/protocols/test1-static-grids.json;--display;${D}/long-name-display.json"
                 -DEXPECT_CODE=3 -DONE_LINE=1
                 "-DEXPECT_TEXT=long-name-display.json: /name: must be at most 100 characters, got 'xxxxxxxxxx"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
add_test(NAME session_run_display_name_escape
         COMMAND ${CMAKE_COMMAND} -DCMD=${BC}
                 "-DARGS=run;${T}/protocols/test1-static-grids.json;--participant;P1;--db;${T}/display-name.sqlite;--observer;sim;--display;${D}/escape-name-display.json"
                 -DEXPECT_CODE=3 -DONE_LINE=1
                 "-DEXPECT_TEXT=escape-name-display.json: /name: must not contain control characters (line breaks, tabs, escapes), got 'booth\\x1b[2J\\n1'"
                 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
set_tests_properties(session_validate_display_name_long session_run_display_name_escape PROPERTIES
                     FIXTURES_REQUIRED "scene;calib;session_protocols")
# Over the cap with a practice criterion: test 1's edges in a warm-up of 495 trials a run, up to 11 runs, and a main
# block of 4950. The message said 5445 trials (one run of each block), below the cap it broke.
set(edges "[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]")
add_preflight_test(criterion-10395
                   "/blocks/0/factors: the session would have up to 10395 trials (11 runs (criterion max_repeats) x 11 edge x 45 repetitions = 5445 in block warm-up + 11 edge x 450 repetitions = 4950 in block main); a session may have at most 10000 trials"
                   "${grid_head} \"sides\": {\"left\": \"measured\", \"right\": \"estimated\"}, \"blocks\": [{\"name\": \"warm-up\", \"practice\": true, \"criterion\": {\"correct\": 0.8, \"max_repeats\": 11}, \"sides\": {\"left\": \"measured\", \"right\": \"none\"}, \"factors\": {\"edge\": ${edges}}, \"repetitions\": 45}, {\"name\": \"main\", \"factors\": {\"edge\": ${edges}}, \"repetitions\": 450}]}")

# What the screen shows, measured on captured frames (run --capture) with the calibration's edge fit: each object's
# blur against its recorded r_screen_px and its edges against its recorded outline (tests/capture_measure.cc).
# subpixel, kernel and distortion measure the blur shown with numpy alone against each trial's unblurred twin
# (tests/capture_kernel.py, tests/capture_distortion.py).
add_executable(capture_measure ${PROJECT_SOURCE_DIR}/tests/capture_measure.cc)
target_link_libraries(capture_measure PRIVATE blurcue_calib blurcue_core)
foreach(case blur place pose window agree thesis aliasing subpixel kernel kernel_motion distortion)
  add_test(NAME capture_${case}
           COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/capture_test.sh ${case} ${BC} $<TARGET_FILE:capture_measure> ${T})
  set_tests_properties(capture_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                       LABELS "gl;session;capture")
endforeach()
set_tests_properties(capture_window PROPERTIES LABELS "gl;session;capture;window")
# The thesis's full-resolution scene and its calibration, made once for capture_place and capture_thesis.
add_test(NAME capture_thesis_full
         COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/capture_test.sh thesis_full ${BC} $<TARGET_FILE:capture_measure> ${T})
set_tests_properties(capture_thesis_full PROPERTIES FIXTURES_SETUP thesis_full LABELS "session;capture")
set_tests_properties(capture_place capture_thesis PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols;thesis_full")

# QUEST+ against python3-questplus, an independent implementation (Debian's).
add_executable(quest_trace ${PROJECT_SOURCE_DIR}/tests/quest_trace.cc)
target_link_libraries(quest_trace PRIVATE blurcue_session)
add_test(NAME quest_agreement
         COMMAND ${BLURCUE_EXPECT} "ok: blurcue's QUEST\\+ agrees" /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/quest_agreement.py $<TARGET_FILE:quest_trace>
                 ${PROJECT_BINARY_DIR}/quest-agreement)

# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(capture_distortion 262 session_depth_arcmin 116 capture_subpixel 114 session_protocol_fuzz 200
               session_report_any_study 65 report_design_quest_per_depth 61 report_design_mixed_blocks 60
               capture_kernel_motion 47 capture_thesis_full 30 report_design_groups 38 report_design_sessions 35
               session_report_aborted 34 session_practice_criterion 34 session_resume 32 capture_kernel 29
               session_recover 25 session_odd_names 25 session_adaptive 25 session_resume_guards 22
               session_resume_exact 22 session_numbers_balanced_counts 22 session_resume_display 21
               session_groups_concurrent 21 session_codebook 21 session_groups_info 19 session_window 18
               session_record_study_names 40 session_record_schema_numbers 12)
# A participant id that differs from one in the record only in case ("s1" after "S1") is another person to the record,
# and was one silently: run says so on the new id's first session (not on S1's second, nor without a near id).
add_test(NAME session_id_differing_in_case_is_said
         COMMAND ${BLURCUE_EXPECT} "participant s1, session 2, [^\n]*completed\n(note: [^\n]*\n)*note: participant s1 is new to this record's study; it also holds S1, differing only in case[^\n]*\n[^\n]*participant S1, session 3, [^\n]*completed(\nnote: [0-9]+ of [0-9]+ trials show [^\n]*)*\n?$"
                 bash -c "rm -f \"$2\" \"$2-wal\" \"$2-shm\" && for id in S1 s1 S1; do \"$1\" run \"$3\" --participant $id --observer sim --db \"$2\" --again 2>/dev/null || exit 1; done"
                 _ ${BC} ${T}/case-ids.sqlite ${T}/protocols/test1-static-grids.json)
set_tests_properties(session_id_differing_in_case_is_said PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols" LABELS session)
