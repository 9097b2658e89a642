# Turned boards (issue 42, item 2): the board turned 0-60 degrees about the table normal (`blurcue synth-scene
# --yaw-deg`), so its edges run diagonally across the pixel grid; tests/phase_check.py runs `blurcue calibrate` and holds
# every section against synth's truth (the applied kernels' second moments, from their arrays): measured and fitted r_px
# median <= 2 %, p90 <= 5 %, nothing flagged, and (turned) the measured readings' signed median within +-0.4 %. Before
# the bins' own spread was modelled (edge_blur.cc, MakeBins) a turned board read +0.7-0.9 % high on these scenes (yaw
# 20/45/60: +0.84/+0.89/+0.74 %; level: +0.42 %), inside the 2 % target but a bias. Scenes under the build dir.
set(TURNED_DIR ${PROJECT_BINARY_DIR}/turned)
set(TURNED_CHECK /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/phase_check.py $<TARGET_FILE:blurcue>)

function(turned_scene name)
  add_test(NAME turned_gen_${name} COMMAND $<TARGET_FILE:blurcue> synth-scene --out ${TURNED_DIR}/${name} --quiet ${ARGN})
  set_tests_properties(turned_gen_${name} PROPERTIES FIXTURES_SETUP turned_${name} LABELS "slow;turned")
endfunction()
function(turned_check name)
  add_test(NAME turned_${name} COMMAND ${BLURCUE_EXPECT} "\nok: physical targets met" ${TURNED_CHECK}
                                       ${TURNED_DIR}/${name} --expect physical --max-flagged 0 ${ARGN})
  set_tests_properties(turned_${name} PROPERTIES FIXTURES_REQUIRED turned_${name} LABELS "slow;turned")
endfunction()

# Disc x a 0.45 px floor, focus inside the board (r 0.9-2.4 px: sub-pixel sections included), noise 0.0025.
foreach(yaw 0 20 45 60)
  turned_scene(${yaw} --yaw-deg ${yaw} --focus-mm 430 --floor-sigma-px 0.45 --noise 0.0025 --seed 3)
endforeach()
# Level: each edge at one sub-pixel phase, where a bias of +0.4 % is the phase's (tests/phase_tests.cmake), not the turn.
turned_check(0)
foreach(yaw 20 45 60)
  turned_check(${yaw} --max-bias 0.004)
endforeach()
# One blur everywhere (no depth change along a section): a disc of 0.8 px x a 0.3 px floor (r 1.00 px), turned 45
# degrees: +0.87 % before, -0.08 % after (level: +0.49 %).
turned_scene(45_fixed --yaw-deg 45 --fixed-r-px 0.8 --floor-sigma-px 0.3 --noise 0.0025 --seed 3)
turned_check(45_fixed --max-bias 0.004)
# Focus in front of the board (r 1.5-4.0 px) at the widest turn, a 0.6 px floor.
turned_scene(60_far --yaw-deg 60 --focus-mm 260 --floor-sigma-px 0.6 --noise 0.0025 --seed 5)
turned_check(60_far --max-bias 0.004)
# Focus in front of the board with r up to 8 px, turned 45 degrees (disc x 0.5 px floor, r 6.2-8.4 px): the far
# squares' sections are short for such a blur, their X-junctions within its reach of the central half used; they are
# measured on a shorter central part (flag `short`, edge_blur.cc) instead of refused. Before: 65 of 77 measured (12
# `crowded`); after: 76 of 77; with the neighbours' distance on the samples' strip and the X-junctions modelled (below)
# 77 of 77, median 0.4 %, p90 0.7 % (was 1.3 %). At least 95 % measured (issue 42, item 3), and the accuracy targets.
turned_scene(45_front --yaw-deg 45 --focus-mm 175 --floor-sigma-px 0.5 --noise 0.003 --seed 17)
turned_check(45_front --min-measured 0.95)
# The same focus with a Gaussian defocus at 45 and 60 degrees and a disc at 60 (r 5.1-8.4 px): 68, 68 and 72 of 77
# measured before (the far squares' sections, too short for their blur even at a fifth of them, refused `crowded`);
# 77 of 77 after the neighbouring edges' distance was taken where the samples' strip meets them (edge_window.cc) and
# the X-junctions joined the profile model (flag `junctions`, edge_junction.h), measured r median 0.3-0.4 %, p90
# 0.9-1.3 %.
foreach(front 45_front_gauss:45:gaussian 60_front_gauss:60:gaussian 60_front:60:disc)
  string(REPLACE ":" ";" parts ${front})
  list(GET parts 0 name)
  list(GET parts 1 yaw)
  list(GET parts 2 psf)
  turned_scene(${name} --psf ${psf} --yaw-deg ${yaw} --focus-mm 175 --floor-sigma-px 0.5 --noise 0.003 --seed 17)
  turned_check(${name} --min-measured 0.95)
endforeach()
# Past ~75 degrees the board's x = 0 end no longer tells which of the two half-turn poses puts edge 1 nearest: at
# 78-89 degrees calibrate took the far edge for edge 1 (pose 175 mm / 180 deg from the truth, section depths 116-118 mm
# off, and nothing said so: the lens fit was still good). Edge 1 is now the nearer first row at the board's middle.
# Past 80 degrees calibrate asks for --board-turned (a board whose edges run into depth is likelier one read turned a
# quarter: cli_names_board_transposed).
foreach(yaw 85 -80)
  add_test(NAME turned_pose_${yaw}_gen COMMAND $<TARGET_FILE:blurcue> synth-scene --out ${TURNED_DIR}/pose${yaw} --quiet
                                               --width 600 --yaw-deg=${yaw} --seed 4)
  add_test(NAME turned_pose_${yaw}
           COMMAND ${BLURCUE_EXPECT} "\nagainst truth: pose 0\\.0[0-9]* mm / 0\\.0[0-9]* deg, section depths within 0\\.[0-9]+ mm"
                   $<TARGET_FILE:blurcue> calibrate ${TURNED_DIR}/pose${yaw}/scene.png --camera ${TURNED_DIR}/pose${yaw}/camera.json
                   --truth ${TURNED_DIR}/pose${yaw}/truth.json --out ${TURNED_DIR}/pose${yaw}-calib.json --board-turned)
  set_tests_properties(turned_pose_${yaw}_gen PROPERTIES FIXTURES_SETUP turned_pose_${yaw} LABELS turned)
  set_tests_properties(turned_pose_${yaw} PROPERTIES FIXTURES_REQUIRED turned_pose_${yaw} LABELS turned)
endforeach()
# The summary says how many used sections were read on a shorter part (it named only those left out).
add_test(NAME turned_45_front_says_short
         COMMAND ${BLURCUE_EXPECT} "\n[1-9][0-9]* of them read on a shorter central part \\(flag short"
                 $<TARGET_FILE:blurcue> calibrate ${TURNED_DIR}/45_front/scene.png --camera ${TURNED_DIR}/45_front/camera.json
                 --out ${TURNED_DIR}/45_front-summary-calib.json)
set_tests_properties(turned_45_front_says_short PROPERTIES FIXTURES_REQUIRED turned_45_front LABELS "slow;turned")
