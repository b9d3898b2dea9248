#!/usr/bin/env node
// decode_log.mjs DBC_PATH CANDUMP_LOG [--csv OUT] [--expect EXPECTED_CSV]
//
// Loads a DBC file with candied (a DBC parser this project did not write) and decodes every
// frame of a candump -L log with it: one CSV row per decoded signal, time_s,message,signal,value
// (physical values as candied computes them), to OUT or to standard output. Frames whose id is
// not in the DBC, or whose length is not the message's, are counted on standard error.
// With --expect, the rows must match EXPECTED_CSV (names exactly, values to 1e-9 relative).
//
// Exit codes: 0 good, 1 the DBC does not load cleanly / a log line is malformed / the rows
// differ from the expected ones, 2 bad arguments or unreadable files.
import { readFileSync, writeFileSync } from 'node:fs';
import { Can, Dbc } from 'candied';

import { loadDbc } from './load_dbc.mjs';
import { compareRows, readCsv } from './expect_csv.mjs';

const usage = 'usage: decode_log.mjs DBC_PATH CANDUMP_LOG [--csv OUT] [--expect EXPECTED_CSV]';

function fail(code, message) {
  console.error(`decode_log: ${message}`);
  process.exit(code);
}

function parseArgs(argv) {
  const args = { positional: [] };
  for (let i = 0; i < argv.length; ++i) {
    const flag = argv[i];
    if (flag === '--csv' || flag === '--expect') {
      if (i + 1 >= argv.length) fail(2, `${flag} needs a path\n${usage}`);
      args[flag.slice(2)] = argv[++i];
    } else if (flag.startsWith('--')) {
      fail(2, `unknown option ${flag}\n${usage}`);
    } else {
      args.positional.push(flag);
    }
  }
  if (args.positional.length !== 2) fail(2, usage);
  [args.dbc, args.log] = args.positional;
  return args;
}

function readText(path) {
  try {
    return readFileSync(path, 'utf8');
  } catch (error) {
    return fail(2, `${path}: cannot read (${error.code ?? error.message})`);
  }
}

// A candump -L line: "(1700000000.000100) can0 022#0103000000000000", with " T" or " R" after
// it from candump -x (transmitted or received by the capturing host). Standard ids have 3 hex
// digits, extended ids 8; remote frames ("R") and CAN FD frames ("##") are not decoded.
const kFrameLine =
    /^\((\d+(?:\.\d+)?)\)\s+(\S+)\s+([0-9A-Fa-f]{3}|[0-9A-Fa-f]{8})#([0-9A-Fa-f]*|R\d?)(?: [TR])?$/;
const kExtendedFlag = 0x80000000;  // how DBC files mark a 29-bit id

function parseFrame(line) {
  const match = kFrameLine.exec(line);
  if (!match || (match[4] !== '' && !match[4].startsWith('R') && match[4].length % 2 !== 0)) {
    return null;
  }
  const [, time_s, , idText, dataText] = match;
  const extended = idText.length === 8;
  const id = parseInt(idText, 16);
  const remote = dataText.startsWith('R');
  const payload = remote ? [] : (dataText.match(/../g) ?? []).map((byte) => parseInt(byte, 16));
  const dbcId = extended ? (id | kExtendedFlag) >>> 0 : id;
  return { time_s, id, extended, remote, payload, dbcId };
}

function decodeLog(logPath, logText, data) {
  const can = new Can();
  can.database = data;
  const messages = new Map([...data.messages.values()].map((m) => [m.id, m]));
  const rows = [];
  const counts = {
    frames: 0, decoded: 0, unknownId: new Map(), wrongLength: 0, remote: 0, malformed: 0,
  };
  logText.split('\n').forEach((rawLine, index) => {
    const line = rawLine.trim();
    if (line === '') return;
    const frame = parseFrame(line);
    if (!frame) {
      counts.malformed += 1;
      console.error(`decode_log: ${logPath}:${index + 1}: not a candump -L frame: ${line}`);
      return;
    }
    counts.frames += 1;
    const message = messages.get(frame.dbcId);
    if (frame.remote) {
      counts.remote += 1;
    } else if (!message) {
      counts.unknownId.set(frame.id, (counts.unknownId.get(frame.id) ?? 0) + 1);
    } else if (frame.payload.length !== message.dlc) {
      counts.wrongLength += 1;
      console.error(`decode_log: ${logPath}:${index + 1}: ${message.name} has ` +
                    `${frame.payload.length} bytes, the DBC says ${message.dlc}`);
    } else {
      const bound = can.decode(can.createFrame(frame.dbcId, frame.payload, frame.extended));
      counts.decoded += 1;
      for (const [name, signal] of bound.boundSignals) {
        rows.push({ time_s: frame.time_s, message: bound.name, signal: name, value: signal.value });
      }
    }
  });
  return { rows, counts };
}

function report(counts) {
  const unknown = [...counts.unknownId.values()].reduce((a, b) => a + b, 0);
  console.error(`decode_log: ${counts.frames} frames: ${counts.decoded} decoded, ${unknown} with ` +
                `an id not in the DBC, ${counts.wrongLength} with a wrong length, ` +
                `${counts.remote} remote; ${counts.malformed} malformed lines`);
  for (const [id, n] of [...counts.unknownId].sort((a, b) => a[0] - b[0])) {
    console.error(`decode_log:   id 0x${id.toString(16).toUpperCase().padStart(3, '0')}: ` +
                  `${n} frames not in the DBC`);
  }
}

const args = parseArgs(process.argv.slice(2));
const data = loadDbc(new Dbc(), args.dbc, readText(args.dbc));
if (!data) process.exit(1);
const { rows, counts } = decodeLog(args.log, readText(args.log), data);
report(counts);

const csvRows = rows.map((r) => `${r.time_s},${r.message},${r.signal},${r.value}`);
const csv = ['time_s,message,signal,value', ...csvRows].join('\n') + '\n';
if (args.csv) {
  try {
    writeFileSync(args.csv, csv);
  } catch (error) {
    fail(2, `--csv ${args.csv}: cannot write (${error.code ?? error.message})`);
  }
} else {
  process.stdout.write(csv);
}
let status = counts.malformed > 0 ? 1 : 0;
if (args.expect) {
  let expected = [];
  try {
    expected = readCsv(args.expect, readText(args.expect));
  } catch (error) {
    fail(2, error.message);
  }
  const mismatches = compareRows(rows, expected);
  for (const m of mismatches) console.error(`decode_log: ${m}`);
  if (mismatches.length > 0) {
    console.error(`decode_log: ${mismatches.length} rows differ from ${args.expect}`);
    status = 1;
  } else {
    console.error(`decode_log: all ${rows.length} values match ${args.expect}`);
  }
}
process.exit(status);
