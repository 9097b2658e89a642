# What a kill -9 of merge, export and report leaves behind (tests/outputs_kill_test.sh): the old output or the whole
# new one, no surviving analysis process, and leftovers that the next run removes. Over the CLI tests' scene.
foreach(case merge export report)
  add_test(NAME outputs_kill_${case}
           COMMAND bash ${PROJECT_SOURCE_DIR}/tests/outputs_kill_test.sh ${case} $<TARGET_FILE:blurcue>
                   ${PROJECT_BINARY_DIR}/cli-test)
  set_tests_properties(outputs_kill_${case} PROPERTIES FIXTURES_REQUIRED "scene;calib;session_protocols"
                       LABELS "gl;outputs" TIMEOUT 120 PASS_REGULAR_EXPRESSION "^ok:|\nok:")
endforeach()
