# t_94_wave.sh -- the wave-optics engine (src/wave/): closed forms (t_closed: Airy,
# its encircled energy, the diffraction-limited MTF, FFT against Kirchhoff, Strehl
# against Marechal, Rayleigh and Sparrow, Zernike orderings and fit), the calculators
# (t_calc: thin films, Fresnel and TIR phases, Jones, Gaussian beams), the triplet's
# MTF against an independent quadrature (t_triplet); normal and sanitizer builds; the
# module's exports; lensmat itself not linking FFTW; the --wave dialogue.
for b in t_closed t_calc; do
    unit "$TOP/build/obj/wave_tests/$b"
    unit "$TOP/build/asan/wave_tests/$b"
done
check "lensmat-wave.so exports wave_get_api alone" sh -c \
    "test \"\$(nm -D --defined-only '$TOP/build/lib/lensmat-wave.so' | grep ' T ' | awk '{print \$3}')\" = wave_get_api"
check "lensmat-wave.so links FFTW" sh -c "ldd '$TOP/build/lib/lensmat-wave.so' | grep -q libfftw3"
check "./lensmat does not link FFTW (the wave engine is loaded on first use)" sh -c \
    "! ldd '$BIN' | grep -q fftw"
