# t_85_rig_gpio.sh -- the libgpiod backend against the kernel's gpio-sim chip in qemu
# (../shared/tools/gpio-vm/run; tests/rig/vm_rig.c inside the guest, tests/rig/vm.rig):
# a line held by another consumer, unknown chip and line, homing against a home
# switch, STEP pulses and DIR counted through sysfs, the laser low when the interlock
# opens, SIGTERM mid-scan.  Each PASS/FAIL line of the guest counts here.
rig_gpio_vm() {
    vm=${GPIO_VM:-$SHARED/tools/gpio-vm/run}     # GPIO_VM: another checkout's copy
    if [ ! -x "$vm" ]; then fail "gpio-vm: $vm not found"; return; fi
    if [ ! -x "$TOP/build/obj/rig_vm/vm_rig" ]; then fail "build/obj/rig_vm/vm_rig not built"; return; fi
    (cd "$TOP" && GPIO_VM_FILES=tests/rig/vm.rig "$vm" build/obj/rig_vm/vm_rig vm.rig) \
        > "$WORK/vm.out" 2>&1
    rc=$?
    tr -d '\r' < "$WORK/vm.out" | grep -E '^(PASS|FAIL)' > "$WORK/vm.res"
    p=$(grep -c '^PASS' "$WORK/vm.res"); f=$(grep -c '^FAIL' "$WORK/vm.res")
    PASSED=$((PASSED + p)); FAILED=$((FAILED + f))
    grep '^FAIL' "$WORK/vm.res" | sed 's/^/vm_rig: /'
    if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then
        fail "gpio-vm exited $rc"; tail -20 "$WORK/vm.out"
    elif [ "$p" -lt 16 ]; then
        fail "gpio-vm: only $p checks ran"; tail -20 "$WORK/vm.out"
    fi
}
rig_gpio_vm
