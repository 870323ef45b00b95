# t_61_trace_ports.sh -- the trace engine on every processor (issue 13).  x86-64: the
# engine built with -march=x86-64 (build/x86-64/, src/trace/module.mk) has no AVX
# instruction outside the two kernels chosen at load, and the engine's tests pass on
# it: the same bits under every kernel this processor runs (t_isa), the lens and
# extreme-case tests with SSE2 forced.
# arm64: every engine's C sources compile with Debian's aarch64 cross compiler
# (gcc-aarch64-linux-gnu, scripts/install-deps.sh), warning-free, and the packet
# kernel comes out as NEON vector code; skipped, saying so, without that compiler.

PT=$WORK/ports
mkdir -p "$PT"
if [ "$(uname -m)" = x86_64 ]; then
    XB=$TOP/build/x86-64
    # no_avx: no VEX/EVEX instruction (v-mnemonic, ymm, zmm) in any object but the
    # AVX2 and AVX-512 kernels
    no_avx() {
        for o in "$XB"/trace/*.o "$XB"/trace/px/*.o; do
            case $o in */tr_pk_avx2.o|*/tr_pk_avx512.o) continue ;; esac
            n=$(objdump -d --no-show-raw-insn "$o" |
                grep -cE '%[yz]mm|^ +[0-9a-f]+:[[:space:]]+v[a-z0-9]+[[:space:]]')
            [ "$n" -eq 0 ] || { echo "$o: $n AVX instructions"; return 1; }
        done
        # and the kernels are there, with the instructions they are built for
        objdump -d "$XB/trace/tr_pk_avx512.o" | grep -q '%zmm' &&
            objdump -d "$XB/trace/tr_pk_avx2.o" | grep -q '%ymm'
    }
    check "trace -march=x86-64: no AVX instruction outside tr_pk_avx2.o, tr_pk_avx512.o" \
        no_avx
    for b in t_physics t_mesh t_watertight t_isa; do unit "$XB/trace_tests/$b"; done
    for b in t_lens t_extreme; do           # the lens packets on the baseline kernel
        printf '#!/bin/sh\nLENSMAT_ISA=sse2 exec "%s"\n' "$XB/trace_tests/$b" > "$PT/${b}_sse2"
        chmod +x "$PT/${b}_sse2"
        unit "$PT/${b}_sse2"
    done
fi

if command -v aarch64-linux-gnu-gcc >/dev/null 2>&1; then
    # the Makefile's BASE flags (imaging's C adds -D_DEFAULT_SOURCE, as its module.mk
    # does); the host's /usr/include after the cross libc for Embree, GSL, libgpiod,
    # readline and OpenCV headers (arch-neutral)
    A64="-std=c11 -D_POSIX_C_SOURCE=200809L -DLENSMAT_VERSION=\"0\" -ffp-contract=off
         -I$TOP/src -I$TOP/build/gen -idirafter /usr/include -Wall -Wextra"
    arm64_syntax() {
        for d in "$TOP"/src/*/; do
            ls "$d"*.c >/dev/null 2>&1 || continue
            x=""
            case $d in */imaging/) x=-D_DEFAULT_SOURCE ;; esac
            # shellcheck disable=SC2086
            aarch64-linux-gnu-gcc $A64 $x -fsyntax-only "$d"*.c 2>> "$PT/arm64.err" || return 1
        done
        [ ! -s "$PT/arm64.err" ] || { cat "$PT/arm64.err"; return 1; }
    }
    check "arm64: every engine's C sources compile (aarch64-linux-gnu-gcc -fsyntax-only)" \
        arm64_syntax
    # the trace engine compiled to objects (the code generator's warnings too, with
    # the module's -O3 -fno-math-errno on its tr_*.c); the packet kernel as NEON
    arm64_trace() {
        for f in "$TOP"/src/trace/*.c; do
            o=-O2
            case $f in */tr_*.c) o="-O3 -fno-math-errno" ;; esac
            # shellcheck disable=SC2086
            aarch64-linux-gnu-gcc $A64 $o -Werror -c "$f" -o "$PT/$(basename "$f" .c).o" ||
                return 1
        done
        aarch64-linux-gnu-objdump -d "$PT/tr_pk_base.o" | grep -qE 'fsqrt[[:space:]]+v[0-9]+\.2d' &&
        aarch64-linux-gnu-objdump -d "$PT/tr_pk_base.o" | grep -qE 'fdiv[[:space:]]+v[0-9]+\.2d' &&
        aarch64-linux-gnu-objdump -t "$PT/tr_isa.o" | grep -q 'tr_pk_step_base'
    }
    check "arm64: the trace engine compiles warning-free, its packet kernel to NEON (fdiv, fsqrt on v.2d)" \
        arm64_trace
else
    echo "t_61_trace_ports: SKIP the arm64 compile: aarch64-linux-gnu-gcc is not installed" \
         "(apt-get install gcc-aarch64-linux-gnu libc6-dev-arm64-cross; scripts/install-deps.sh does)"
fi
