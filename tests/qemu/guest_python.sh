#!/bin/sh
# Runs inside the qemu guest (busybox, vcan0 up; see qemu_guest.py): drive_hil runs the drive on
# vcan0 while the Python client (tools/python/imdrive, with the host's interpreter shipped by
# python_bundle.py) commands it (python_guest.py). python_test.py checks what it emitted.
set -u
drive_hil /hil/tests/qemu/hil.toml --can vcan0 --node 1 --cpu 1 --duration-s 200 \
  > /tmp/hil.log 2>&1 &
HIL=$!
start=$(cut -d ' ' -f 1 /proc/uptime)
PYTHONPATH=/py python3 -B /hil/python_guest.py > /tmp/python.log 2>&1
echo "python exit $? (uptime $start -> $(cut -d ' ' -f 1 /proc/uptime) s)" >> /tmp/python.log
kill -TERM $HIL; wait $HIL
echo "drive_hil exit $?" >> /tmp/hil.log
emit python.log /tmp/python.log
emit hil.log /tmp/hil.log
exit 0
