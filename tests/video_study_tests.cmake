# The shipped video study (protocols/video-ball-depth.json) on a 4-frame take of the tests' own, made once as a
# fixture into the CLI tests' folder where the session tests' copy of the protocol points (tests/video_study_test.sh):
# it validates and previews; a headless simulated session killed -9 and resumed answers every planned trial once;
# a simulated session's every frame matches the take's truth (the take frame, each ball's blur and streak);
# its report analyses it and describes its scene as a video; bad video scenes are one problem naming the field.
set(T ${PROJECT_BINARY_DIR}/cli-test)
set(VIDEO_STUDY_TEST bash ${PROJECT_SOURCE_DIR}/tests/video_study_test.sh)
add_test(NAME video_study_take COMMAND ${BLURCUE_EXPECT} "(^|\n)ok:" ${VIDEO_STUDY_TEST} take $<TARGET_FILE:blurcue> ${T})
set_tests_properties(video_study_take PROPERTIES FIXTURES_SETUP video_take)
foreach(case validate kill9 frames report bad_scene procedure rolling two_takes)
  add_test(NAME video_study_${case} COMMAND ${BLURCUE_EXPECT} "(^|\n)ok:" ${VIDEO_STUDY_TEST} ${case} $<TARGET_FILE:blurcue> ${T})
  set_tests_properties(video_study_${case} PROPERTIES FIXTURES_REQUIRED "video_take;session_protocols"
                       LABELS "gl;session")
endforeach()
# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(video_study_report 20 video_study_kill9 12)
