# t_39_pupil.sh -- first-order pupils (src/paraxial/pupil.c, tests/unit_pupil.c),
# real rays aimed at the stop (src/trace/tr_aim.c, tests/trace/t_aim.c), and the
# --pupil dialogue: pupil data, chief rays, spots and fans per field and wavelength.
unit "$TOP/build/obj/unit_pupil"
unit "$TOP/build/asan/unit_pupil"
unit "$TOP/build/obj/trace_tests/t_aim"
unit "$TOP/build/asan/trace_tests/t_aim"
