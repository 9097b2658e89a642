# The documentation as a reader meets it (tests/docs_check.py): the README under 2,500 words and naming no path
# outside the repository, every relative link and anchor of README.md and docs/*.md resolving.
add_test(NAME docs_links_and_length
         COMMAND ${BLURCUE_ANALYSIS_PYTHON} ${PROJECT_SOURCE_DIR}/tests/docs_check.py ${PROJECT_SOURCE_DIR})
set_tests_properties(docs_links_and_length PROPERTIES LABELS docs)

# docs/commands.md is what `blurcue COMMAND --help` prints today (scripts/commands_doc.py --check).
add_test(NAME docs_commands_current
         COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" ${BLURCUE_ANALYSIS_PYTHON} ${PROJECT_SOURCE_DIR}/scripts/commands_doc.py $<TARGET_FILE:blurcue>
                 --check ${PROJECT_SOURCE_DIR}/docs/commands.md)
set_tests_properties(docs_commands_current PROPERTIES LABELS docs)

# The README's first study, command by command, from an installed and moved prefix in an empty folder
# (tests/readme_walk_test.sh).
add_test(NAME readme_first_study
         COMMAND ${BLURCUE_EXPECT} "^ok:|\nok:" bash ${PROJECT_SOURCE_DIR}/tests/readme_walk_test.sh ${PROJECT_BINARY_DIR}
                 ${PROJECT_BINARY_DIR}/readme-walk)
set_tests_properties(readme_first_study PROPERTIES LABELS "gl;docs" TIMEOUT 600)
# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(readme_first_study 31)

# The suite's own rules over every registered test (tests/suite_check.py): no PASS_REGULAR_EXPRESSION (CTest ignores
# the exit code with it), no skip counted as a pass, no timeout used as a speed check.
add_test(NAME suite_checks_exit_codes
         COMMAND /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/suite_check.py ${CMAKE_CTEST_COMMAND} ${PROJECT_BINARY_DIR})
set_tests_properties(suite_checks_exit_codes PROPERTIES LABELS docs)
