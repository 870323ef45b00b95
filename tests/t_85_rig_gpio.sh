# t_85_rig_gpio.sh -- the libgpiod backend against the kernel's gpio-sim chip in qemu
# (../shared/tools/gpio-vm/run; tests/rig/vm_rig.c inside the guest, tests/rig/vm.rig):
# a line held by another consumer, unknown chip and line, homing against a home
# switch, STEP pulses and DIR counted through sysfs, the laser low when the interlock
# opens, SIGTERM mid-scan; then lensmat --rig itself on that chip (tests/rig/
# vm_dialogue.sh: a session and its replay).  Each PASS/FAIL line of the guest counts.
rig_gpio_vm() {   # rig_gpio_vm MIN_CHECKS FILES PROGRAM ARGS...
    min=$1; files=$2; shift 2
    vm=${GPIO_VM:-$SHARED/tools/gpio-vm/run}     # GPIO_VM: another checkout's copy
    if [ ! -x "$vm" ]; then fail "gpio-vm: $vm not found"; return; fi
    if [ ! -x "$TOP/$1" ]; then fail "$1 not built"; return; fi
    (cd "$TOP" && GPIO_VM_FILES="$files" "$vm" "$@") > "$WORK/vm.out" 2>&1
    rc=$?
    tr -d '\r' < "$WORK/vm.out" | grep -E '^(PASS|FAIL)' > "$WORK/vm.res"
    p=$(grep -c '^PASS' "$WORK/vm.res"); f=$(grep -c '^FAIL' "$WORK/vm.res")
    PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
    grep '^FAIL' "$WORK/vm.res" | sed "s|^|$(basename "$1"): |"
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
        fail "gpio-vm $1 exited $rc"; tail -20 "$WORK/vm.out"
    elif [ "$p" -lt "$min" ]; then
        fail "gpio-vm $1: only $p checks ran"; tail -20 "$WORK/vm.out"
    fi
}
rig_gpio_vm 16 tests/rig/vm.rig build/obj/rig_vm/vm_rig vm.rig
# lensmat needs readline in the guest: a folder with it under its soname
mkdir -p "$WORK/vmlibs"
for l in $(ldd "$BIN" | grep -o '/[^ ]*libreadline[^ ]*'); do cp -L "$l" "$WORK/vmlibs/"; done
rig_gpio_vm 7 "tests/rig/vm.rig lensmat build/lib/lensmat-rig.so $WORK/vmlibs" \
    tests/rig/vm_dialogue.sh
