# blurcue validate: the shipped protocols pass (without file checks: the demo scene may not exist yet), and a broken
# protocol is rejected with exit 3 and every problem at once, each naming its JSON pointer.
# Without --seed, the seed `blurcue run` gives P1 (FNV-1a 64 of "test2-moving-balls/P1"), so the hash is the run's.
foreach(case "pre-research-depth-matching|ok: 28 trials" "test1-static-grids|ok: 13 trials"
        "test2-moving-balls|ok: 74 trials for participant P1 with seed 12146811198788962045 \\(hash [0-9a-f]+\\)"
        "test3-no-board|ok: 74 trials")
  string(FIND "${case}" "|" bar)
  string(SUBSTRING "${case}" 0 ${bar} study)
  math(EXPR bar "${bar} + 1")
  string(SUBSTRING "${case}" ${bar} -1 expect)
  add_test(NAME cli_validate_${study}
           COMMAND ${BLURCUE_EXPECT} "${expect}" $<TARGET_FILE:blurcue> validate ${PROJECT_SOURCE_DIR}/protocols/${study}.json --no-files)
endforeach()
add_test(NAME cli_validate_explicit_seed
         COMMAND ${BLURCUE_EXPECT} "ok: 74 trials for participant P4 with seed 4 \\(hash [0-9a-f]+\\)" $<TARGET_FILE:blurcue> validate ${PROJECT_SOURCE_DIR}/protocols/test2-moving-balls.json --no-files
                 --participant P4 --seed 4)
# A staircase that stops at its 6th reversal (30 trials at each of two speeds at most): the list holds all 60, the
# session shows up to 60, and validate says "up to" (it said "60 trials", the maximum, where runs take fewer).
add_test(NAME cli_validate_stop_rule_up_to
         COMMAND ${BLURCUE_EXPECT} "ok: up to 60 trials for participant P1 [^\n]*\n  staircase up to 60 \\(forced_choice"
                 $<TARGET_FILE:blurcue> validate ${PROJECT_SOURCE_DIR}/protocols/staircase-ball-gain.json --no-files)

set(BROKEN_PROTOCOL ${PROJECT_SOURCE_DIR}/tests/data/broken-protocol.json)
foreach(expect "/factors/pattern/0/speed_cm_s: a speed must be a number in [0.1, 100] cm/s, got -3"
               "/factors/edge/1: an edge must be an integer in [1, 101], got 102"
               "/repetitons: unknown key (did you mean \"repetitions\"?), got 2"
               "/scene/background: no such file")
  string(MAKE_C_IDENTIFIER "${expect}" id)
  add_test(NAME cli_validate_broken_${id}
           COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue> "-DARGS=validate;${BROKEN_PROTOCOL}" -DEXPECT_CODE=3
                   "-DEXPECT_TEXT=broken-protocol.json: ${expect}" -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
endforeach()
# Without file checks the missing scene is not a problem; the other three still are.
add_test(NAME cli_validate_broken_no_files
         COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue> "-DARGS=validate;${BROKEN_PROTOCOL};--no-files"
                 -DEXPECT_CODE=3 "-DEXPECT_TEXT=(3 problems)" -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)

# The JSON Schema is itself valid draft 2020-12, accepts the four shipped protocols and rejects the broken one
# (only where python3 has jsonschema; the C++ validator above does not depend on it).
# Debian's interpreter first: the one that sees python3-jsonschema (a python3 earlier on PATH may not).
if(EXISTS /usr/bin/python3 AND NOT Python3_EXECUTABLE)
  set(Python3_EXECUTABLE /usr/bin/python3)
endif()
find_package(Python3 COMPONENTS Interpreter QUIET)
if(Python3_Interpreter_FOUND)
  execute_process(COMMAND ${Python3_EXECUTABLE} -c "import jsonschema" RESULT_VARIABLE no_jsonschema
                  OUTPUT_QUIET ERROR_QUIET)
  if(no_jsonschema EQUAL 0)
    set(check "import json, sys, jsonschema\n\
V = jsonschema.Draft202012Validator\n\
s = json.load(open(sys.argv[1])); V.check_schema(s)\n\
errors = lambda f: list(V(s).iter_errors(json.load(open(f))))\n\
bad = [f for f in sys.argv[2:-1] if errors(f)]\n\
assert not bad, bad\n\
assert errors(sys.argv[-1]), 'broken protocol accepted'\n\
print('schema ok')")
    set(P ${PROJECT_SOURCE_DIR}/protocols)
    # Every shipped protocol (the schema file itself aside).
    file(GLOB SHIPPED_PROTOCOLS ${P}/*.json)
    list(FILTER SHIPPED_PROTOCOLS EXCLUDE REGEX "protocol\\.schema\\.json$")
    add_test(NAME protocol_schema
             COMMAND ${BLURCUE_EXPECT} "schema ok" ${Python3_EXECUTABLE} -c "${check}" ${P}/protocol.schema.json ${SHIPPED_PROTOCOLS}
                     ${BROKEN_PROTOCOL})

  endif()
endif()

# A factor nothing reads is refused with the nearest name that is read (exit 3, the one problem on one line).
add_test(NAME cli_validate_misspelt_factor
         COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue>
                 "-DARGS=validate;${PROJECT_SOURCE_DIR}/tests/data/misspelt-factor.json;--no-files" -DEXPECT_CODE=3
                 "-DEXPECT_TEXT=misspelt-factor.json: /factors/secton: no part of blurcue reads a factor secton (did you mean section?); to record it as a label nobody reads, name it label_secton"
                 -DONE_LINE=1 -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
# Participant information: a choice in the wrong case, and a key the protocol does not ask for, are refused (exit 2)
# with the one meant, before anything is recorded (over the session tests' copy of the protocols and their scene).
set(CLI_T ${PROJECT_BINARY_DIR}/cli-test)
foreach(case "handedness=Left|--info handedness=Left: must be one of left, right, both (did you mean left?)"
             "handednes=left|(participant_info), not handednes (did you mean handedness?)")
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 info)
  list(GET parts 1 expect)
  string(MAKE_C_IDENTIFIER "${info}" id)
  add_test(NAME cli_run_info_did_you_mean_${id}
           COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue>
                   "-DARGS=run;${CLI_T}/protocols/groups-and-info.json;--participant;P1;--db;${CLI_T}/info-did-you-mean.sqlite;--observer;sim;--info;age=34;--info;${info};--info;vision=normal"
                   -DEXPECT_CODE=2 "-DEXPECT_TEXT=${expect}" -DONE_LINE=1
                   -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
  set_tests_properties(cli_run_info_did_you_mean_${id} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols")
endforeach()
# A protocol file that is not there: exit 3 naming it, the same from validate, plan, preview and run (run records
# nothing: no record file is made).
foreach(cmd validate preview run)
  set(extra)
  if(cmd STREQUAL "preview")
    set(extra ";--out;${PROJECT_BINARY_DIR}/cli-test/missing-protocol.png")
  elseif(cmd STREQUAL "run")
    set(extra ";--participant;P1;--observer;sim;--db;${PROJECT_BINARY_DIR}/cli-test/missing-protocol.sqlite")
  endif()
  add_test(NAME cli_${cmd}_missing_protocol
           COMMAND ${CMAKE_COMMAND} -DCMD=$<TARGET_FILE:blurcue>
                   "-DARGS=${cmd};${PROJECT_BINARY_DIR}/cli-test/no-such-protocol.json${extra}" -DEXPECT_CODE=3
                   "-DEXPECT_TEXT=no-such-protocol.json: cannot open file: No such file or directory" -DONE_LINE=1
                   -P ${PROJECT_SOURCE_DIR}/tests/expect_failure.cmake)
endforeach()
