# t_10_unit.sh -- the C unit tests of the core, optimised and under ASan/UBSan.
unit "$TOP/build/obj/unit_classic"
unit "$TOP/build/asan/unit_classic"
