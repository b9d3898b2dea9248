#!/bin/sh
# expect.sh CODE PATTERN COMMAND...: runs COMMAND and passes when it exits with CODE and its
# combined output matches the extended regular expression PATTERN.
code=$1; pattern=$2; shift 2
output=$("$@" 2>&1); status=$?
printf '%s\n' "$output"
if [ "$status" -ne "$code" ]; then echo "expect.sh: exit code $status, expected $code"; exit 1; fi
if ! printf '%s\n' "$output" | grep -Eq -- "$pattern"; then
  echo "expect.sh: output does not match: $pattern"; exit 1
fi
