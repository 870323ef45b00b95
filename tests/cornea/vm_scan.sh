#!/bin/sh
# vm_scan.sh -- lensmat --cornea-scan on the gpio-sim chip, inside the gpio-vm guest
# (tests/t_91_cornea_loop.sh copies lensmat, the rig, trace, cornea and topo modules and
# tests/cornea/vm_scan.rig into /data): a 10-point scan moved and exposed on the real
# kernel chip, fitted, the laser line low afterwards, and its grep'd record replaying
# to the same record.  Prints PASS/FAIL lines; exit 0 or 1.
cd /data || exit 1
export LD_LIBRARY_PATH=/data/vmlibs LENSMAT_LIBDIR=/data LENSMAT_THREADS=1
fails=0
ok() { if [ "$1" = 0 ]; then echo "PASS $2"; else echo "FAIL $2"; fails=$((fails+1)); fi; }
sed "s/^chip .*/chip $GPIO_CHIP/" vm_scan.rig > chip.rig
printf 'biconic\nchip.rig\ngpiod\n2\nspiral\n10\n2\nmodel\n7.8\n-0.26\n0.75\n0\n0.1732\n0.1\n2\n0\n0.04\n14\n1\n0\nrep1\nn\n' > answers
./lensmat --cornea-scan -i answers r1.rec > out 2> err; rc=$?
ok $rc "lensmat --cornea-scan on the gpio-sim chip: 10 points moved, exposed, fitted"; cat err >&2
grep -q "^Chip open ($GPIO_CHIP)" r1.rec; ok $? "the record names the real chip"
grep -q '^Pattern spiral: 10 targets to 2 deg, 10 planned, 10 exposed' r1.rec; ok $? "10 exposures"
grep -q '^Spots: 10 fitted' rep1.txt; ok $? "the report file: 10 spots fitted"
[ "$(cat $GPIO_SIM/sim_gpio24/value)" = 0 ]; ok $? "laser low after the scan"
grep input: r1.rec | sed 's/^input: //; s/^rep1$/rep2/' > answers
./lensmat --cornea-scan -i answers r2.rec > out2 2> err2; rc=$?
ok $rc "its grep'd record replays on the chip"
cmp rep1.txt rep2.txt; ok $? "... to the same report"
[ $fails = 0 ]
