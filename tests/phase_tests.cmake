# Identifiability per section (issue 42, item 1): scenes of the level geometry (every board edge along the pixel rows,
# so each edge is sampled at one sub-pixel phase), focus inside the board, rendered by `blurcue synth-scene` with and
# without a filter on the sampled image (--post-filter); tests/phase_check.py runs `blurcue calibrate` and holds each
# section against synth's truth (the kernels' and the post filter's taps' second moments, from their arrays). Scenes
# are written under the build dir. docs/definitions.md explains `phase_limited`.
set(PHASE_DIR ${PROJECT_BINARY_DIR}/phase)
set(PHASE_CHECK /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/phase_check.py $<TARGET_FILE:blurcue>)

function(phase_scene name)
  add_test(NAME phase_gen_${name} COMMAND $<TARGET_FILE:blurcue> synth-scene --out ${PHASE_DIR}/${name} --quiet ${ARGN})
  set_tests_properties(phase_gen_${name} PROPERTIES FIXTURES_SETUP phase_${name} LABELS "slow;phase")
endfunction()
function(phase_check name scene regex)
  add_test(NAME ${name} COMMAND ${BLURCUE_EXPECT} ${regex} ${PHASE_CHECK} ${PHASE_DIR}/${scene} ${ARGN})
  set_tests_properties(${name} PROPERTIES FIXTURES_REQUIRED phase_${scene} LABELS "slow;phase")
endfunction()

# Filtered after sampling: a Gaussian of std 0.45 px on the sampled image (taps 0.072, 0.855, 0.072: 0.145 px^2) over a
# disc x 0.2 px floor, noise 0.0025. Before the check, edge 5 (its edge 0.58 px past a pixel row) read 0.70 px for a
# true 0.87 px, edges 3 and 6 -6 %; the fitted model median 3.7 %, p90 6.5 %.
phase_scene(gauss --focus-mm 430 --floor-sigma-px 0.2 --post-filter gaussian --post-sigma-px 0.45 --noise 0.0025 --seed 3)
phase_check(phase_filtered_gauss gauss "\nok: filtered targets met" --expect filtered)
# ... and the targets catch the readings without the check (exit 1 with edge 5's sections named).
add_test(NAME phase_filtered_gauss_unchecked_caught
         COMMAND ${BLURCUE_EXPECT} --exit 1 "target missed: edge 5 section 4 reads 0.[67][0-9]* px for 0.86[0-9]* px, unflagged"
                 ${PHASE_CHECK} ${PHASE_DIR}/gauss --expect filtered --no-phase-check)
set_tests_properties(phase_filtered_gauss_unchecked_caught PROPERTIES FIXTURES_REQUIRED phase_gauss LABELS "slow;phase")
# A camera's JPEG over a wider post filter (std 0.5 px), noise 0.003.
phase_scene(jpeg --focus-mm 430 --floor-sigma-px 0.2 --post-filter gaussian --post-sigma-px 0.5 --noise 0.003
            --jpeg-quality 92 --seed 5)
phase_check(phase_filtered_jpeg jpeg "\nok: filtered targets met" --expect filtered)
# Gaussian optics near focus (0.1 px floor) under a post filter of std 0.6 px: the filter is most of the blur.
phase_scene(wide --focus-mm 400 --psf gaussian --floor-sigma-px 0.1 --post-filter gaussian --post-sigma-px 0.6
            --noise 0.002 --seed 7)
phase_check(phase_filtered_wide wide "\nok: filtered targets met" --expect filtered)
# Physically smooth optics (disc x a 0.45 px floor before the pixel aperture; Gaussian x 0.35 px): accuracy as before
# the check, and no section flagged.
phase_scene(disc --focus-mm 430 --floor-sigma-px 0.45 --noise 0.0025 --seed 3)
phase_check(phase_physical_disc disc "\nok: physical targets met" --expect physical --max-flagged 0)
phase_scene(gaussopt --focus-mm 440 --psf gaussian --floor-sigma-px 0.35 --noise 0.002 --jpeg-quality 95 --seed 12)
phase_check(phase_physical_gauss gaussopt "\nok: physical targets met" --expect physical --max-flagged 0)
# The issue's lower floor, std 0.2 px: near focus the blur is 0.4-0.5 px, and on edges near a pixel centre the profile
# does not tell the PSF's shape, yet the shape moved the size: a disc fitted best by noise read 8-20 % high (edge 7),
# measured p90 6.3-8.4 %, 2-6 sections off unflagged and 10-11 correct ones flagged (their jump judged against a
# 0.35 px Gaussian stuck at its own floor). Now read with the Gaussian shape under 0.7 px where the shape is
# ambiguous (an independent erf fit of the same pixels read them within 1 %). Edges within 0.1 px of a pixel centre
# at r 0.4-0.5 px still scatter 10-20 % with the noise: a section whose standard error with the shape held is over 2 %
# is flagged and joins the lens fit at its reading (23-24 of 77 here; none at floor 0.45, phase_physical_disc).
phase_scene(disc02 --focus-mm 430 --floor-sigma-px 0.2 --noise 0.003 --seed 22)
phase_check(phase_physical_disc_floor02 disc02 "too unsure near a pixel centre.*\nok: physical targets met" --expect physical --max-flagged 30)
phase_scene(gauss02 --focus-mm 430 --psf gaussian --floor-sigma-px 0.2 --noise 0.003 --seed 26)
phase_check(phase_physical_gauss_floor02 gauss02 "\nok: physical targets met" --expect physical --max-flagged 30)
# An adversary's sweep: focus 500 mm puts edges 8-11 at r 0.40-0.50 px near pixel centres; before, measured p90 6.5 %
# and the fitted model 2.1 / 7.1 % (the optics alone's family reading stuck at r = 0 held it low).
phase_scene(gauss02f500 --focus-mm 500 --psf gaussian --floor-sigma-px 0.2 --noise 0.0025 --seed 680)
phase_check(phase_physical_floor02_focus500 gauss02f500 "\nok: physical targets met" --expect physical --max-flagged 30)
# JPEG 95 over the same floor (the sweep's seed 204): the compression takes the tails of edge 8's section 2 (0.41 px,
# its edge 0.06 px past a pixel centre) and the blur fit's Gaussian reading collapsed to 0.02 px, unflagged (its
# standard error was not taken: no curvature in r there). Now infinite, it is flagged. A JPEG acts on the sampled
# image, so the filtered rule holds: every section within max(0.05 px, 10 %) or flagged, the model within 2 / 5 %.
phase_scene(gauss02jpeg --focus-mm 470 --psf gaussian --floor-sigma-px 0.2 --noise 0.0025 --jpeg-quality 95 --seed 204)
phase_check(phase_physical_floor02_jpeg95 gauss02jpeg "\nok: filtered targets met" --expect filtered)
# Focus on edge 1 (the thesis's set-up) and a JPEG of quality 90 over a post filter of std 0.45 px: only edges 1-8 are
# under 2 px and the JPEG's blocks blur which family fits best (4 of 15 alike): 14 sections are flagged (edges 1 and 2,
# their families' readings 0.77-0.91 px apart for a true 0.86-0.92 px) and predicted by the model, held to their
# ranges. Without the check edges 2 and 3 read 10-18 % low unflagged.
phase_scene(edge1 --floor-sigma-px 0.2 --post-filter gaussian --post-sigma-px 0.45 --noise 0.003 --jpeg-quality 90
            --seed 8)
phase_check(phase_filtered_focus_edge1 edge1 "phase_limited.*\nok: filtered targets met" --expect filtered)
# Sharpened after sampling (an unsharp mask of amount 0.3 over a Gaussian of std 0.6 px: -0.105 px^2) over a disc x
# 0.5 px floor: before the check every section read 3-10 % high and the model median 5.3 %, p90 8.8 %.
phase_scene(sharpen --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.6 --post-amount 0.3
            --noise 0.0025 --seed 6)
phase_check(phase_filtered_sharpen sharpen "\nok: filtered targets met" --expect filtered)
# Stronger sharpening (amount 0.5 over 0.6 px: -0.176 px^2), the bench's open failure: the families' optics had the
# blur fit's shape (a disc, on a sharpened profile) and a wrong mask (amount 0.15) fitted best; 35 sections read 10-25 %
# high unflagged, the model median 9.1 %, p90 22.0 %. Now each family's optics shape is fitted with its radius.
phase_scene(sharpen05 --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.6 --post-amount 0.5
            --noise 0.0025 --seed 6)
phase_check(phase_filtered_sharpen_05 sharpen05 "\nok: filtered targets met" --expect filtered)
# Amount 0.7 (-0.246 px^2): near focus the mask cancels up to 97 % of the optics' second moment (truth 0.16 px from
# optics of 1.0 px), where a 2 % error in the optics' reading moves the section's by 0.1 px: those sections are flagged
# (35 of 77, edges 4-8) and every other one holds the rule. They join the lens fit at their readings (each unsure
# alone, the fit pools them): left out, nothing near focus pinned the floor and the model read 0.19 px for 0.16 px
# (median 2.4 %, p90 19.1 % here; 1.2-2.3 / 22-29 % on five other seeds). Now median 0.6-1.1 %, p90 1.8-8.1 % over
# the six seeds (this one 0.9 / 3.9 %). Fitted to r itself, those sections counted as surely as the optics' own
# reading, where the mask magnifies its error 5-8 times; now the model is fitted to the optics' readings (sqrt(r^2 - 4V))
# and the filter added back: p90 1.0-5.7 % on seeds 1-4 and 6 (this one 1.5 / 2.0 %; on main 1.8-13.4 %), 8.3 % on
# seed 5 (a neighbouring mask chosen). The model's own standard error there (edges as clusters) reaches 14-28 % near
# focus: calibrate names those depths (407-453 mm; 404-457 mm with the readings' own error, 0.4 % of the optics' blur,
# in it: tests/undetermined_coverage.py) "not determined within 5 %", and every section the model misses by
# more than 5 % lies within them (--undetermined-covers). Seed 2 (p90 5.7 %: edges 5-6, inside the named depths) holds
# that at 10 %.
phase_scene(sharpen07 --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.6 --post-amount 0.7
            --noise 0.0025 --seed 6)
phase_check(phase_filtered_sharpen_07 sharpen07
            "[2-4][0-9] of them phase_limited but joined at their readings.*\ncalibrate: the model's blur is not determined within 5 % at depths 4[01][0-9]-4[45][0-9] mm.*\nok: filtered targets met"
            --expect filtered --undetermined-covers)
# A mask photo's calib.json (with model.fitted_to and each section's r_fitted_se_px) is read by render: the reader
# refused fields it did not know.
set_tests_properties(phase_filtered_sharpen_07 PROPERTIES FIXTURES_SETUP phase_sharpen07_calib)
add_test(NAME phase_filtered_sharpen_07_render
         COMMAND ${BLURCUE_EXPECT} "ball at edge 5: depth [0-9.]+ mm, blur fitted" $<TARGET_FILE:blurcue> render
                 --calib ${PHASE_DIR}/sharpen07-calib-filtered.json --background ${PHASE_DIR}/sharpen07/scene.png
                 --object ball --at-edge 5 --blur fitted --out ${PHASE_DIR}/sharpen07-ball.png)
set_tests_properties(phase_filtered_sharpen_07_render PROPERTIES FIXTURES_REQUIRED "phase_sharpen07;phase_sharpen07_calib"
                     LABELS "slow;phase;gl")
phase_scene(sharpen07_seed2 --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.6
            --post-amount 0.7 --noise 0.0025 --seed 2)
phase_check(phase_filtered_sharpen_07_seed2 sharpen07_seed2
            "calibrate: the model's blur is not determined within 5 % at depths 4[01][0-9]-4[4-6][0-9] mm.*\nok: filtered targets met"
            --expect filtered --undetermined-covers --fitted-p90 0.10)

# The Gaussian post filter's ends (0.35 and 0.8 px, the bench's levels). At 0.35 px the optics alone fitted best and
# 7 sections (edge 4) read 10-12 % high unflagged; now the 0.35 px family is chosen.
phase_scene(gauss035 --focus-mm 430 --floor-sigma-px 0.2 --post-filter gaussian --post-sigma-px 0.35 --noise 0.0025
            --seed 4)
phase_check(phase_filtered_gauss_035 gauss035 "\nok: filtered targets met" --expect filtered)
phase_scene(gauss08 --focus-mm 430 --floor-sigma-px 0.2 --post-filter gaussian --post-sigma-px 0.8 --noise 0.0025
            --seed 4)
phase_check(phase_filtered_gauss_08 gauss08 "\nok: filtered targets met" --expect filtered)
# Masks between the families (a camera's filter is never exactly one): amount 0.3 over a Gaussian of 0.8 px (-0.192
# px^2) read as the family 0.15 at 1.0 px left 7 sections (edge 5, truth 0.49 px) at 0.40-0.42 px unflagged; amount
# 0.25 over 0.9 px (-0.2025 px^2), read as 0.3 at 0.8 px, 13 sections (edges 4 and 7) 10-13 % high unflagged. Now the
# family that fits best is refined between the families (phase_fit.h) and the 0.8 px masks are families.
phase_scene(sharpen_off_grid --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.8
            --post-amount 0.3 --noise 0.0025 --seed 6)
phase_check(phase_filtered_sharpen_off_grid sharpen_off_grid "\nok: filtered targets met" --expect filtered)
phase_scene(sharpen_09 --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.9
            --post-amount 0.25 --noise 0.0025 --seed 5)
phase_check(phase_filtered_sharpen_09 sharpen_09 "fitted between the families.*\nok: filtered targets met"
            --expect filtered --undetermined-covers)
# The same mask at seed 12, noise 0.002 (tests/undetermined_coverage.py's held-out seed): the search between the
# families stayed at the grid's 0.7 over 0.6 px and the grid's 0.3 over 0.8 px was taken (chi-square per point 3.5):
# edges 4-7 read 7-14 % high unflagged (13 sections off the rule), the model p90 11.5 %. Searched along the valley of
# one second moment (phase_fit.cc): 0.32 over 0.83 px, none off, the model 0.6 / 0.9 %.
phase_scene(sharpen_09_seed12 --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.9
            --post-amount 0.25 --noise 0.002 --seed 12)
phase_check(phase_filtered_sharpen_09_seed12 sharpen_09_seed12 "fitted between the families.*\nok: filtered targets met"
            --expect filtered --undetermined-covers)
# A mask that cancels the optics' whole blur on four edges (0.7 over 0.8 px, 1.34 px of it) with focus in front of the
# board (330 mm; a first-time experimenter's scene): their 28 sections read 0 px. Joined to the lens fit at that bound
# as values, they put its focus at 375 mm and drew 0.65, 0.25, 0.12, 0.45 px on edges 1-4 (true 0) and 1.02 px for a
# true 0.82 px on edge 6 (model p90 far past 5 %). As bounds (PhaseCheck::bound) with the mask beyond the floor taken
# from the thin lens too (model.cancel_px2): focus 330.7 mm, every section's model within median 0.5 %, p90 0.6 %.
phase_scene(sharpen_07_08_front --focus-mm 330 --post-filter sharpen --post-sigma-px 0.8 --post-amount 0.7 --noise 0.004
            --seed 3)
phase_check(phase_filtered_sharpen_07_08_front sharpen_07_08_front "28 sections read 0 px, a bound.*\nok: filtered targets met"
            --expect filtered)
# Amount 0.5 over 0.8 px (-0.32 px^2): the mask cancels the whole second moment near focus (truth 0 on edges 4-8),
# where 55-57 sections are flagged; 1-3 others read 0.07-0.1 px off unflagged before. The lens model breaks here
# (no thin lens bends to that), so the sections alone are held, and the model's misses must lie within the depths
# calibrate names not determined within 5 %: before, it named 364-501 mm from the standard error alone and the model
# missed edges 2 and 10 outside them (0.80 px for 0.71 px, 0.71 for 0.62 px); now 35 sections read 0 px there (a
# bound), the readings' error is 3 % of the optics' blur and it names 342-539 mm, the whole board.
phase_scene(sharpen_05_08 --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.8
            --post-amount 0.5 --noise 0.0025 --seed 2)
phase_check(phase_filtered_sharpen_05_08 sharpen_05_08
            "cancels the whole blur at 4[0-9][0-9]-4[0-9][0-9] mm.*\nok: filtered targets met" --expect filtered
            --sections-only --undetermined-covers)
# The board's outer edges read against the table, whose texture moves a reading more than its standard error says:
# over 200 scenes (10 kinds of mask and turn, seeds 1-10 and 17-26) five outer-edge sections read 10-15 % high
# unflagged, none inner. Level, 0.5 over 0.8 px, seed 6: edge 11 section 6 read 0.88 px for 0.80; turned 30 deg, seed
# 18: edge 11 section 2 0.70 px for 0.62. Now such a section off the lens fit's prediction by more than max(0.04 px,
# 8 %) less its standard error is flagged after the fit (FlagOffTheLensFit, PhaseCheck.OuterEdgeSectionOffTheLensFit...).
phase_scene(sharpen_05_08_seed6 --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.8
            --post-amount 0.5 --noise 0.002 --seed 6)
phase_check(phase_filtered_sharpen_05_08_outer_edge sharpen_05_08_seed6
            "after the lens fit 1 more on the board's outer edge.*\nok: filtered targets met" --expect filtered
            --sections-only --undetermined-covers)
phase_scene(turn30_sharpen_seed18 --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.6
            --post-amount 0.7 --noise 0.002 --seed 18 --yaw-deg 30)
phase_check(phase_turned_30_sharpen_07_outer_edge turn30_sharpen_seed18
            "after the lens fit 1 more on the board's outer edge.*\nok: filtered targets met" --expect filtered
            --fitted-p90 0.10 --undetermined-covers)
# Held out (tests/undetermined_coverage.py, seeds 27-36): the mask 0.35 over 0.9 px focused at 450 mm is refined to
# 0.25 over 1.04 px on seed 33, along its valley of one second moment, and edge 3 read 6-13 % low (section 2: 0.63 px
# for 0.72 px) unflagged. The valley's ends read it 0.55-0.68 px: a section at few phases whose reading moves by more
# than max(0.04 px, 8 %) between them is flagged and joins the lens fit (PhaseCheck.SectionTheMaskValleyReadsApart...).
phase_scene(sharpen_035_09_f450_seed33 --focus-mm 450 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.9
            --post-amount 0.35 --noise 0.002 --seed 33)
phase_check(phase_filtered_sharpen_035_09_valley sharpen_035_09_f450_seed33
            "[1-9][0-9]* where masks along the chosen one's valley.*\nok: filtered targets met" --expect filtered
            --sections-only --undetermined-covers)
# The bench's Gaussian of 0.35 px (bench measure --quick, seed 1): edge 7 lies 0.09 px past a pixel centre, its profile
# a handful of samples, and its seven sections of one true blur (0.62 px) read 0.58-0.70 px under the family that fits
# (the families' spread 0.03 px): section 1 at 0.70 px (+12.5 %) unflagged. Now a section off the line through its
# edge's other sections by more than max(0.04 px, 8 %) is flagged where a filter was chosen.
phase_scene(gauss035_bench --focus-mm 430 --floor-sigma-px 0.2 --post-filter gaussian --post-sigma-px 0.35
            --noise 0.0025 --seed 1)
phase_check(phase_filtered_gauss_035_bench gauss035_bench "off the line through their edge.*\nok: filtered targets met"
            --expect filtered)
# Boards turned a few degrees under a filter after sampling (an adversary's finding): sections whose edge crosses a
# pixel row or more along the part measured sample every phase and were not read per family, so the photo's filter
# went unread on them. Turned 3 deg under a mask of amount 0.7 over 0.6 px, main read 28 sections off the rule
# unflagged (edge 4: 0.73-0.75 px for 0.32-0.36 px) and the model median 16 %, p90 60 %; under a Gaussian of 0.45 px,
# edge 4 10-12 % low. Turned 20 deg (every section at every phase): mask model median 46 %, p90 282 %; Gaussian
# sections 10-13 % low, model median 7 %, p90 12 %. Now every section under 2 px is read with the family chosen.
# A family's filter is read on both axes (calib/family_esf.h, the exact separable model): turned 20 deg the mask's
# model p90 went from 4.9-6.9 % (the taps along the nearest axis alone) to 2.4 %. Turned 30 deg (edges 15-25 deg off
# the pixel axes in the image) both pass on main too. Turned 45 and 60 deg (edges 24-44 deg off them), main read no
# family beyond 25 deg: mask 58-59 sections off the rule unflagged, model median 47-58 %, p90 255-275 %; Gaussian model
# median 3.7-5.7 %, p90 6.8-7.5 %, 1-2 sections off. Now the Gaussian meets every target; the mask (read as 0.3 over
# 0.8 px there: it fits the profiles as well as the true 0.7 over 0.6 px, 7931 against 7944 at 45 deg) misses by two
# sections each and the lens model's p90: at 45 deg edge 11 sections 4 and 7 (0.62 px for 0.52, 0.75 for 0.85: every
# family alike reads them so; main flagged them) and the model p90 8.6 %; at 60 deg edge 1 section 1 (2.54 px for 2.26,
# over 2 px: the blur fit's reading, as on main) and edge 5 section 7 (0.61 px for 0.13: not read per family, its
# phase check empty, as on main) and the model median 2.3 %, p90 30.6 % (near focus, truths 0.12-0.2 px, where the
# mask cancels most of the optics' blur). Held to what they read, named here (docs/independent-truth.md): 45 deg the
# model within p90 10 %, 60 deg the sections alone (--sections-only), each at most the two sections named off.
# With the lens model fitted to the optics' readings where a mask is chosen (phase_flags.cc), fitted median / p90 on
# this branch (main after the two-axis model -> this): 20 deg 0.6 / 2.4 -> 0.6 / 1.3 %, 30 deg 0.3 / 3.7 -> 0.5 / 5.6 %
# (edge 8, 0.11 px low near focus, inside the depths calibrate names not determined within 5 %, 422-439 mm, now
# 407-456 mm with the readings' own error: held to 10 % and to that), 45 deg 1.7 / 8.6 -> 1.0 / 1.1 % (now held to 5 %), 60 deg 2.3 / 30.6 -> 2.5 / 10.8 %.
# The four misses (issue 42), found: a section at every phase kept only the 0.1 px bins of 3 samples or more, as a level
# edge's, and a far section of a board turned 45-60 deg puts about 2 in each: edge 11 section 7 at 45 deg kept 11 of
# ~150 bins (0.75 px for 0.85), edge 5 section 7 at 60 deg under 6 (not read per family at all: 0.61 px for 0.13
# unflagged); every bin with a sample is now kept there: 0.84 px, and 0.09 px flagged (the mask cancels most of its
# blur). Sections over 2 px were the blur fit's optics alone, which under the mask reads about the optics' blur:
# edge 1 section 1 at 60 deg 2.54 px for 2.26, now read with the chosen family, 2.38 px. Edge 11 section 4 at 45 deg
# lies on the board's outer edge, beside the table, whose wood grain crosses it obliquely and leaves a ramp across
# the window (the table 2 % of the step darker at the edge than 7 px out; the same scene with a flat table read it
# 0.53 px for 0.52): read again with the table's slope it reads 0.56 px against 0.62, and such a section is flagged.
# Now 45 deg: none off the rule, model median 1.3 %, p90 6.9 % (0.011 px high at truths 0.13-0.16 px, 426-440 mm,
# inside the depths calibrate names not determined within 5 %, 419-441 mm: held to 10 % and to that, as 30 deg);
# 60 deg: none off, model 1.1 / 2.2 % (held to 5 %). Seeds 2 and 9 (45, 60 deg): sections off the rule unflagged
# 0, 3, 3, 2 -> 1, 0, 0, 2 and model p90 1.4, 17.8, 16.0, 32.9 -> 1.2, 3.9, 1.7, 13.3 %; their misses left are on
# the outer edges at 0.46-0.64 px, 10-14 % high, where the table's slope moves them less than the flag's 8 %. Those
# are now flagged by their readings' standard errors (phase_section_rule_turned below): 1, 0, 0, 2 -> 0.
foreach(turn 3 20 30 45 60)
  set(model --fitted-p90 0.05 --undetermined-covers)
  set(off 0)
  # Turned 20 deg: where the search between the families follows the valley of one second moment (phase_fit.cc), the
  # grid's own 0.7 over 0.6 px (the true mask) is chosen, and the model misses edges 5-7 by up to 18 % near focus (p90
  # 8.8 %; it was 1.3 % with a refined family a little off the truth), all within the depths named (407-456 mm).
  if(turn EQUAL 20 OR turn EQUAL 30 OR turn EQUAL 45)
    set(model --fitted-p90 0.10 --undetermined-covers)
  endif()
  phase_scene(turn${turn}_sharpen --focus-mm 430 --floor-sigma-px 0.5 --post-filter sharpen --post-sigma-px 0.6
              --post-amount 0.7 --noise 0.0025 --seed 6 --yaw-deg ${turn})
  phase_check(phase_turned_${turn}_sharpen_07 turn${turn}_sharpen
              "and [1-9][0-9]* at every phase.*\nok: filtered targets met" --expect filtered ${model}
              --max-off ${off})
  phase_scene(turn${turn}_gauss --focus-mm 430 --floor-sigma-px 0.2 --post-filter gaussian --post-sigma-px 0.45
              --noise 0.0025 --seed 3 --yaw-deg ${turn})
  phase_check(phase_turned_${turn}_gauss turn${turn}_gauss
              "and [1-9][0-9]* at every phase.*\nok: filtered targets met" --expect filtered)
endforeach()
# Physical boards turned 45 and 60 deg (no filter after sampling): every section under 2 px is read per family, the
# optics alone is chosen and nothing flagged. On main 7 and 0 sections were read (no family beyond 25 deg off an
# axis), so the first part of the expected output fails there; read with the taps along the nearest axis alone they
# chose a Gaussian of 0.35 px, and with the exact model that Gaussian fitted 1.9 better in 8187 at 60 deg (a filter is
# now taken only where it beats the optics alone by 25).
foreach(turn 45 60)
  phase_scene(turn${turn}_disc --focus-mm 430 --floor-sigma-px 0.45 --noise 0.0025 --seed 3 --yaw-deg ${turn})
  phase_check(phase_turned_${turn}_physical turn${turn}_disc
              "and [1-9][0-9] at every phase.*fits best as the optics alone.*\nok: physical targets met"
              --expect physical --max-flagged 0)
endforeach()

# Where calibrate names depths at which the lens model is not determined within 5 % (the mask scene above: edges 4-7),
# what uses the model there says so: render (the ball at edge 5, 415 mm), animate (balls rolling edge 3 -> 8), preview, validate and run (a grid study over edges
# 2 and 5 with fitted blur on one side): the trial at edge 5 is named, edge 2's (356 mm) is not. Before, all three drew
# or planned 0.20 px there without a word.
file(WRITE ${PHASE_DIR}/undetermined-grids.json [=[
{"name": "undetermined-grids", "version": 1, "description": "fitted blur inside and outside the depths the mask scene's model is not determined at",
 "scene": {"background": "sharpen07/scene.png", "calib": "sharpen07-calib-filtered.json"},
 "content": {"type": "grid", "cells": 5}, "task": "forced_choice", "factors": {"edge": [2, 5]},
 "sides": {"left": "fitted", "right": "none"}, "repetitions": 1, "counterbalance": "none",
 "instructions": "Which grid fits the scene?", "responses": {"left": "Left", "right": "Right"},
 "timing": {"stimulus_ms": 500, "inter_trial_ms": 0},
 "display": {"width_px": 640, "height_px": 480, "fullscreen": false, "monitor": 0}}
]=])
add_test(NAME phase_undetermined_render_note
         COMMAND ${BLURCUE_EXPECT} "ball at edge 5: depth 41[0-9].[0-9] mm, blur fitted.*\nnote: the fitted blur at 41[0-9] mm is the lens model's estimate, not a result within 5 %: the model is not determined within 5 % at 4[01][0-9]-4[45][0-9] mm \\(its error [^;]*; why: [^\n]*sharpen07-calib-filtered.json /model/undetermined\\)"
                 $<TARGET_FILE:blurcue> render --calib ${PHASE_DIR}/sharpen07-calib-filtered.json
                 --background ${PHASE_DIR}/sharpen07/scene.png --object ball --at-edge 5 --blur fitted
                 --out ${PHASE_DIR}/undetermined-ball.png)
add_test(NAME phase_determined_render_no_note
         COMMAND ${BLURCUE_EXPECT} "^ball at edge 2: depth 35[0-9].[0-9] mm, blur fitted[^\n]*\n$"
                 $<TARGET_FILE:blurcue> render --calib ${PHASE_DIR}/sharpen07-calib-filtered.json
                 --background ${PHASE_DIR}/sharpen07/scene.png --object ball --at-edge 2 --blur fitted
                 --out ${PHASE_DIR}/determined-ball.png)
add_test(NAME phase_undetermined_validate_note
         COMMAND ${BLURCUE_EXPECT} "ok: 2 trials.*\n  note: 1 of 2 trials show the fitted blur where it is not determined within 5 %; the first: the fitted blur at 4[0-4][0-9] mm is the lens model's estimate"
                 $<TARGET_FILE:blurcue> validate ${PHASE_DIR}/undetermined-grids.json)
add_test(NAME phase_undetermined_run_note
         COMMAND ${BLURCUE_EXPECT} "2 of 2 trials answered.*completed\nnote: 1 of 2 trials show the fitted blur where it is not determined within 5 %"
                 $<TARGET_FILE:blurcue> run ${PHASE_DIR}/undetermined-grids.json --db ${PHASE_DIR}/undetermined.db
                 --participant P1 --observer sim --again)
add_test(NAME phase_undetermined_animate_note
         COMMAND ${BLURCUE_EXPECT} "12 frames .*\nnote: the fitted blur at 4[0-4][0-9] mm is the lens model's estimate"
                 $<TARGET_FILE:blurcue> animate --calib ${PHASE_DIR}/sharpen07-calib-filtered.json
                 --background ${PHASE_DIR}/sharpen07/scene.png --left fitted --right none --from-edge 3 --to-edge 8
                 --speed-cm-s 6 --fps 5 --log ${PHASE_DIR}/undetermined-animate.csv --frames ${PHASE_DIR}/undetermined-frames)
# calibrate's own summary: its advice names those depths and its table puts the model's value there in parentheses
# (edges 5 and 6, 421 and 441 mm; edge 4 at 401 mm and edge 7 at 461 mm outside them stay bare).
add_test(NAME phase_undetermined_calibrate_table
         COMMAND ${BLURCUE_EXPECT} "what to do: [^\n]*the model's value \\(an estimate at 4[01][0-9]-4[45][0-9] mm, where it is not determined within 5 %\\)\n.*\nmodel: the model's blur is not determined within 5 % at depths 4[01][0-9]-4[45][0-9] mm[^\n]*\n.*\n   4 [^\n(]*\n   5 [^\n]* +\\(0\\.[0-9][0-9]\\)\n   6 [^\n]* +\\(0\\.[0-9][0-9]\\)\n   7 [^\n(]*\n.*, in parentheses where it is not determined within 5 %"
                 $<TARGET_FILE:blurcue> calibrate ${PHASE_DIR}/sharpen07/scene.png --camera ${PHASE_DIR}/sharpen07/camera.json
                 --out ${PHASE_DIR}/sharpen07-calib-table.json)
set_tests_properties(phase_undetermined_calibrate_table PROPERTIES FIXTURES_REQUIRED phase_sharpen07 LABELS "slow;phase")
add_test(NAME phase_undetermined_preview_note
         COMMAND ${BLURCUE_EXPECT} "2 distinct stimuli of 2 trials.*\nnote: 1 of 2 trials show the fitted blur where it is not determined within 5 %"
                 $<TARGET_FILE:blurcue> preview ${PHASE_DIR}/undetermined-grids.json --out ${PHASE_DIR}/undetermined-sheet.png)
set_tests_properties(phase_undetermined_render_note phase_determined_render_no_note phase_undetermined_validate_note
                     phase_undetermined_run_note phase_undetermined_animate_note phase_undetermined_preview_note
                     PROPERTIES FIXTURES_REQUIRED "phase_sharpen07;phase_sharpen07_calib" LABELS "slow;phase;gl")
# The claim "the model's blur is not determined within 5 % at depths X-Y mm" checked by simulation (issue 42,
# tests/undetermined_coverage.py): 7 kinds of scene, 6 seeds each (11-16; the criterion was chosen on seeds 1-6),
# noise 0.002-0.003. Outside the named depths at most 10 % of the sections may miss max(0.05 px, 5 %), the fitted
# model's p90 there at most 5 %, the controls (no filter after sampling, a Gaussian after it) name nothing, and every
# section is within max(0.05 px, 10 %) of the truth or flagged (issue 42's per-section rule). Before,
# the propagated standard error alone named 400-510 mm under the mask that cancels the whole blur near focus (0.35
# over 0.9 px, focus 450 mm) and the model missed 52 % of the sections outside (fitted p90 18 % there; seeds 1-6), and
# its errors / standard error had p90 2.7-2.9 under the other masks; now the readings' own error (0.4 % of the optics'
# blur, 3 % where a mask cancels the whole blur) is in the standard error: seeds 11-16, 0-3 % miss outside, fitted p90
# 1.0-3.3 % there, errors / standard error p90 1.4-1.7 (2.5 under 0.5 over 0.8 px, where every depth is named). On
# seeds 11-16 main's blurcue fails it: 0.35 over 0.9 px 61 % miss outside (p90 31 %), 0.5 over 0.8 px 46 % (p90 16 %),
# errors / standard error p90 2.6-8.3. The
# misses left (3 % under 0.25 over 0.9 px): seed 12 alone, where the grid's family 0.3 over 0.8 px was kept (chi-square
# per point 3.5) and edges 4-7 read 7-12 % high, the model with them; its 4 seeds 11-14 alone put the p90 at 6.1 %.
add_test(NAME phase_undetermined_coverage
         COMMAND ${BLURCUE_EXPECT}
                 "sharpen 0.35/0.9 f450 \\(6 scenes\\): depths named on 6.*\nnone \\(6 scenes\\): depths named on 0: none.*\nok: outside the depths named not determined within 5 %, the model holds on every mask"
                 /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/undetermined_coverage.py $<TARGET_FILE:blurcue>
                 ${PHASE_DIR}/coverage --seeds 11,12,13,14,15,16)
set_tests_properties(phase_undetermined_coverage PROPERTIES LABELS "slow;phase")
# Issue 42's per-section rule by simulation on turned boards (tests/undetermined_coverage.py's turned kinds): 45 and 60
# deg under the mask of amount 0.7 over 0.6 px (the phase_turned_*_sharpen_07 scenes), held-out seeds 11 and 13 (noise
# 0.003, 0.0025): every section within max(0.05 px, 10 %) of the truth or flagged phase_limited, and the model's claim
# as above (the level kinds above are held to the rule too: none off on seeds 11-16, on main as now). On seeds 11-16
# main left 2 sections off the rule unflagged, both at 60 deg on the board's outer edges (seed 11 edge 1 section 6,
# 0.759 px for 0.683 px; seed 13 edge 11 section 1, 0.568 px for 0.505 px), and on seeds 2 and 9 three more (45 deg
# seed 2 edge 11 section 5; 60 deg seed 9 edge 1 section 7, edge 11 section 6): there the table's texture enters the
# profile's noise, and their readings' standard errors were 4.5-9.4 % (the inner edges' p90 2 %). A section at every
# phase whose two standard errors exceed the target is now flagged (phase_check.cc, kSeSpan): none off, 29 more flagged
# on those 16 scenes (653 -> 682, all on the outer edges), the fitted model unchanged. Four scenes, about 35 s CPU.
add_test(NAME phase_section_rule_turned
         COMMAND ${BLURCUE_EXPECT}
                 "turned 45 sharpen 0\\.7/0\\.6 \\(2 scenes\\).*turned 60 sharpen 0\\.7/0\\.6 \\(2 scenes\\).*\nok: outside the depths named not determined within 5 %, the model holds on every mask, and every section within max\\(0\\.05 px, 10 %\\) or flagged"
                 /usr/bin/python3 ${PROJECT_SOURCE_DIR}/tests/undetermined_coverage.py $<TARGET_FILE:blurcue>
                 ${PHASE_DIR}/coverage_turned --seeds 11,13
                 --masks "turned 45 sharpen 0.7/0.6,turned 60 sharpen 0.7/0.6")
set_tests_properties(phase_section_rule_turned PROPERTIES LABELS "slow;phase")
# Started first on a fresh clone: seconds in one ctest -j2 run (cmake/BlurcueHelpers.cmake, set_test_costs).
set_test_costs(phase_undetermined_coverage 156 phase_section_rule_turned 45)
