#!/bin/sh
# Runs inside the qemu guest (busybox, vcan0 up; see qemu_guest.py). drive_hil runs the drive
# against the simulated motor on vcan0 while drive_monitor, as the host would, enables it, steps
# the speed, stops sending (the watchdog must trip) and clears the fault. With GPIO=1 (aarch64
# virt: the PL061 is gpiochip0) the board lines are used too, and two more runs check the
# enable interlock and an injected fault. The files it emits are checked on the host by
# hil_test.py; this script only sequences and records.
set -u
. /hil/env
S=/hil/tests/qemu
NODE="--can vcan0 --node 1"
# The loop on CPU 1 under SCHED_FIFO, the rest of the guest (drive_monitor, the CAN I/O thread,
# this script) on CPU 0, as on a board with a core set aside for control. On one emulated CPU
# the loop, late on every tick, would leave the rest only the kernel's 5 % real-time reserve.
RT="--cpu 1"
say() { echo "guest_hil: $*"; }
send() { drive_monitor send $NODE "$@" --wait-heartbeat-s 5 --wait-ack-s 2; }

# The state of the newest telemetry row (the CSV's second-to-last column).
state_now() { tail -n 1 /tmp/telemetry.csv 2>/dev/null | awk -F, '{print $(NF-1)}'; }
# The drive counts simulated time, the waits wall-clock time: an emulated aarch64 guest runs the
# loop at a fifth of real time or less on a busy host, so a 1 s watchdog takes 5 s or more here.
wait_state() {  # wait_state STATE SECONDS; false if the drive did not get there in time
  n=0
  while [ "$(state_now)" != "$1" ] && [ $n -lt $(($2 * 10)) ]; do sleep 0.1; n=$((n + 1)); done
  say "state $(state_now) after $((n / 10)).$((n % 10)) s (waited for $1)"
  [ "$(state_now)" = "$1" ]
}
# The drive went somewhere unexpected: stop it and ship what there is for the host's report.
abort() {
  say "aborting: $*"
  tail -n 3 /tmp/telemetry.csv
  kill -TERM $HIL 2>/dev/null; wait $HIL
  kill -INT $WATCH 2>/dev/null; wait $WATCH
  for f in telemetry.csv hil.log latency.json commands.log; do [ -f /tmp/$f ] && emit $f /tmp/$f; done
  exit 1
}

GPIO_ARGS=""
if [ "$GPIO" = 1 ]; then
  say "GPIO error paths"
  drive_hil $S/hil.toml $NODE --gpio-chip gpiochip7 --fault-line 5 > /tmp/gpio_errors.log 2>&1
  echo "exit $?" >> /tmp/gpio_errors.log
  drive_hil $S/hil.toml $NODE --gpio-chip gpiochip0 --fault-line 9 >> /tmp/gpio_errors.log 2>&1
  echo "exit $?" >> /tmp/gpio_errors.log
  emit gpio_errors.log /tmp/gpio_errors.log

  say "enable interlock: line 4 is an active-high enable input and reads low"
  drive_hil $S/hil.toml $NODE $RT --gpio-chip gpiochip0 --enable-line 4 --duration-s 30 \
    > /tmp/interlock_hil.log 2>&1 &
  HIL=$!
  send enable > /tmp/interlock.log 2>&1
  echo "exit $?" >> /tmp/interlock.log
  kill -TERM $HIL; wait $HIL
  emit interlock.log /tmp/interlock.log
  # The same line active-low reads as asserted: the run below is enabled through it.
  GPIO_ARGS="--gpio-chip gpiochip0 --enable-line 4 --enable-active-low --fault-line 5 --timing-line 6"
fi

say "main run"
drive_hil $S/hil.toml $NODE $RT $GPIO_ARGS --duration-s 100 --latency-report /tmp/latency.json \
  > /tmp/hil.log 2>&1 &
HIL=$!
drive_monitor watch $NODE --csv /tmp/telemetry.csv --no-table > /tmp/watch.log 2>&1 &
WATCH=$!
send set-telemetry-rate 50 > /tmp/commands.log 2>&1
# The calibration is 25.6 ms simulated; a guest starved by a busy host runs the loop at a
# tenth of real time or less, and the first telemetry rows wait for set-telemetry-rate.
wait_state idle 40 || abort "no idle after calibration"
send enable >> /tmp/commands.log 2>&1
# Keep the watchdog fed until the drive runs, then step the speed to 30 rad/s for 6 s.
drive_monitor send $NODE set-speed 0 --repeat-hz 10 --for-s 20 --wait-heartbeat-s 5 >> /tmp/commands.log 2>&1 &
KEEP=$!
wait_state running 25 || { kill -INT $KEEP; abort "not running"; }
kill -INT $KEEP; wait $KEEP
echo "marker step" >> /tmp/commands.log
drive_monitor send $NODE set-speed 30 --repeat-hz 10 --for-s 6 --wait-heartbeat-s 5 >> /tmp/commands.log 2>&1
echo "marker silence" >> /tmp/commands.log
wait_state fault 20 || abort "no watchdog fault"  # the command watchdog (1 s simulated)
send clear-faults >> /tmp/commands.log 2>&1
wait_state idle 40 || abort "no idle after clear_faults"
sleep 1
kill -TERM $HIL; wait $HIL
echo "drive_hil exit $?" >> /tmp/hil.log
sleep 0.5  # the final heartbeat reaches the monitor
kill -INT $WATCH; wait $WATCH
for f in telemetry.csv hil.log latency.json commands.log watch.log; do emit $f /tmp/$f; done

say "motor parameters over CAN: unconfigured start, refused writes, a whole motor file, a save"
rm -f /tmp/motor.rec
drive_hil $S/hil.toml $NODE --parameters /tmp/motor.rec --duration-s 100 > /tmp/param_hil.log 2>&1 &
HIL=$!
P="drive_monitor parameters $NODE --wait-s 5 --wait-heartbeat-s 5"
{
  sleep 1
  echo "step read"; $P; echo "exit $?"
  echo "step negative"; $P --set Rs_Ohm=-1; echo "exit $?"
  echo "step motor file"
  $P --motor-file /hil/hal_sim/motors/seed000.toml --save --motor-out /tmp/motor_out.toml
  echo "exit $?"
  echo "step no leakage"; $P --set Lm_H=0.5; echo "exit $?"
} > /tmp/parameters.log 2>&1
say "commissioning at standstill: the nameplate, then drive_monitor identify"
{
  $P --set rated_voltage_V=220 --set rated_current_A=2.5 --set rated_frequency_Hz=50
  drive_monitor identify $NODE --wait-s 5 --wait-heartbeat-s 5 --timeout-s 60 \
    --motor-out /tmp/identified.toml
  echo "exit $?"
} > /tmp/identify.log 2>&1
kill -TERM $HIL; wait $HIL
# The next power-up starts from the saved record: calibrated, then idle.
drive_hil $S/hil.toml $NODE --parameters /tmp/motor.rec --duration-s 6 > /tmp/param_hil2.log 2>&1
echo "drive_hil exit $?" >> /tmp/param_hil2.log
for f in parameters.log identify.log param_hil.log param_hil2.log motor_out.toml identified.toml; do
  [ -f /tmp/$f ] && emit $f /tmp/$f
done

if [ "$GPIO" = 1 ]; then
  say "injected overvoltage at 0.3 s simulated"
  drive_hil $S/hil_fault.toml $NODE $RT --gpio-chip gpiochip0 --fault-line 5 --duration-s 100 \
    > /tmp/fault_hil.log 2>&1 &
  HIL=$!
  rm -f /tmp/telemetry.csv
  drive_monitor watch $NODE --csv /tmp/telemetry.csv --no-table > /dev/null 2>&1 &
  WATCH=$!
  wait_state fault 20
  kill -TERM $HIL; wait $HIL
  echo "drive_hil exit $?" >> /tmp/fault_hil.log
  kill -INT $WATCH; wait $WATCH
  cp /tmp/telemetry.csv /tmp/fault_telemetry.csv
  emit fault_hil.log /tmp/fault_hil.log
  emit fault_telemetry.csv /tmp/fault_telemetry.csv
fi
exit 0
