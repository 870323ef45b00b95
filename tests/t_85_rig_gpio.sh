# t_85_rig_gpio.sh -- the libgpiod backend against the kernel's gpio-sim chip in qemu
# (../shared/tools/gpio-vm/run; tests/rig/vm_rig.c inside the guest, tests/rig/vm.rig):
# a line held by another consumer, unknown chip and line, homing against a home
# switch, STEP pulses and DIR counted through sysfs, the laser low when the interlock
# opens, SIGTERM mid-scan; then lensmat --rig itself on that chip (tests/rig/
# vm_dialogue.sh: a session and its replay).  Each PASS/FAIL line of the guest counts
# (gpio_vm, tests/run.sh).
gpio_vm 16 tests/rig/vm.rig build/obj/rig_vm/vm_rig vm.rig
# lensmat needs readline in the guest: a folder with it under its soname
mkdir -p "$WORK/vmlibs"
for l in $(ldd "$BIN" | grep -o '/[^ ]*libreadline[^ ]*'); do cp -L "$l" "$WORK/vmlibs/"; done
gpio_vm 7 "tests/rig/vm.rig lensmat build/lib/lensmat-rig.so $WORK/vmlibs" \
    tests/rig/vm_dialogue.sh
