# blurcue synth-take and blurcue track end to end (tests/track_test.sh); the tracker against a ground-truth take is
# src/track/tracker_test.cc.
add_test(NAME track_cli COMMAND bash ${PROJECT_SOURCE_DIR}/tests/track_test.sh $<TARGET_FILE:blurcue>
                                ${PROJECT_BINARY_DIR}/track-test)
set_tests_properties(track_cli PROPERTIES PASS_REGULAR_EXPRESSION "^ok:|\nok:")
