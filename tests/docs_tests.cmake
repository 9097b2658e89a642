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

# The sources' shape (issue 41, scripts/source_shape.py): no file in src/ over 800 lines, and at most --max-long
# functions over 120 lines (issue 41's rule: 8), each with a `// long: <why>` line above it (none today).
add_test(NAME source_shape
         COMMAND ${BLURCUE_EXPECT} "(^|\n)ok: [0-9]+ functions over 120 lines" /usr/bin/python3
                 ${PROJECT_SOURCE_DIR}/scripts/source_shape.py ${PROJECT_SOURCE_DIR}/src --max-long 8 --max-unjustified 0)
set_tests_properties(source_shape PROPERTIES LABELS docs)
# ... and the check itself catches what it is for, at the default limits: a 127-line function without a reason and
# an 801-line header.
string(REPEAT "  Step();\n" 125 source_shape_body)
file(WRITE ${PROJECT_BINARY_DIR}/source-shape-test/src/module/long.cc "void Long() {\n${source_shape_body}}\n")
string(REPEAT "// a line\n" 801 source_shape_body)
file(WRITE ${PROJECT_BINARY_DIR}/source-shape-test/src/module/big.h "${source_shape_body}")
add_test(NAME source_shape_catches_a_long_function
         COMMAND ${BLURCUE_EXPECT} --exit 1
                 "file over 800 lines: src/module/big.h \\(801\\).*127 lines: src/module/long.cc:1 void Long\\(\\) \\{ - NO REASON.*FAIL: 1 functions over 120 lines \\(limit 8\\), 1 of them without a reason \\(limit 0\\), 1 files over 800 lines"
                 /usr/bin/python3 ${PROJECT_SOURCE_DIR}/scripts/source_shape.py ${PROJECT_BINARY_DIR}/source-shape-test/src)
set_tests_properties(source_shape_catches_a_long_function PROPERTIES LABELS docs)
