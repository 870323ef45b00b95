#!/bin/sh
# vm_dialogue.sh -- lensmat --rig on the gpio-sim chip, inside the gpio-vm guest
# (tests/t_85_rig_gpio.sh copies lensmat, the module and this rig into /data): a
# replayed session homes (the home switches tripped through sysfs by this script),
# moves, exposes, and its record replays to the same record on the real chip.
# Prints PASS/FAIL lines; exit 0 or 1.
cd /data || exit 1
export LD_LIBRARY_PATH=/data/vmlibs LENSMAT_LIBDIR=/data
fails=0
ok() { if [ "$1" = 0 ]; then echo "PASS $2"; else echo "FAIL $2"; fails=$((fails+1)); fi; }
# The home switches as a model of real ones: tripped 1 s in (the seek reaches them),
# released when DIR of m1a (line 6) turns away from home (the pull-off), tripped again
# 50 ms after it turns back (the slow locate), released at the second pull-off.
hs() { for j in 18 19 20 21 22 23; do echo "$1" > $GPIO_SIM/sim_gpio$j/pull; done; }
switches() {
    sleep 1; hs pull-up; phase=0; n=0
    while [ $phase -lt 3 ] && [ $n -lt 20000 ]; do
        d=$(cat $GPIO_SIM/sim_gpio6/value); n=$((n+1))
        if [ $phase = 0 ] && [ "$d" = 1 ]; then hs pull-down; phase=1
        elif [ $phase = 1 ] && [ "$d" = 0 ]; then usleep 50000; hs pull-up; phase=2
        elif [ $phase = 2 ] && [ "$d" = 1 ]; then hs pull-down; phase=3; fi
        usleep 1000
    done
}
run() {   # run REC: the session, answers from the file 'answers'
    for j in 18 19 20 21 22 23; do echo pull-down > $GPIO_SIM/sim_gpio$j/pull; done
    switches &                      # the home switches as a model (GRBL homing)
    ./lensmat --rig -i answers "$1" > out 2> err; rc=$?
    wait
    return $rc
}
sed "s/^chip .*/chip $GPIO_CHIP/" vm.rig > chip.rig     # the guest's chip, whatever its name
printf '%s\n' chip.rig gpiod home joints -14.9 -15 -20 -20 -15 -15 expose 200 quit > answers
run r1.rec; ok $? "lensmat --rig on the gpio-sim chip: home, move, expose"; cat err >&2
grep -q 'Chip open: gpiochip' r1.rec; ok $? "the record names the real chip"
grep -q 'Exposed 200 ms' r1.rec; ok $? "the exposure ran"
[ "$(cat $GPIO_SIM/sim_gpio24/value)" = 0 ]; ok $? "laser low after the session"
grep input: r1.rec > answers
run r2.rec; ok $? "its grep'd record replays"
cmp r1.rec r2.rec; ok $? "... to the same record"
grep -q 'Step timing: SCHED_FIFO' out; ok $? "real-time scheduling was asked for and said"
[ $fails = 0 ]
