// Compares decoded rows with an expected CSV (time_s,message,signal,value; '#' lines are
// comments): the same rows in the same order, values equal to 1e-9 relative.

export function readCsv(path, text) {
  const lines = text.split('\n').map((line) => line.trim());
  const rows = [];
  lines.forEach((line, index) => {
    if (line === '' || line.startsWith('#') || line === 'time_s,message,signal,value') return;
    const [time_s, message, signal, value, ...rest] = line.split(',');
    if (value === undefined || rest.length > 0 || Number.isNaN(Number(value))) {
      throw new Error(`${path}:${index + 1}: expected time_s,message,signal,value, got ${line}`);
    }
    rows.push({ time_s, message, signal, value: Number(value), where: `${path}:${index + 1}` });
  });
  return rows;
}

function close(a, b) {
  return Math.abs(a - b) <= 1e-9 * Math.max(1, Math.abs(a), Math.abs(b));
}

/// The differences, as messages; empty when the rows match.
export function compareRows(actual, expected) {
  const problems = [];
  const n = Math.max(actual.length, expected.length);
  for (let i = 0; i < n; ++i) {
    const a = actual[i];
    const e = expected[i];
    if (!a) {
      problems.push(`${e.where}: expected ${e.message}.${e.signal} = ${e.value}, nothing decoded`);
    } else if (!e) {
      problems.push(`decoded ${a.message}.${a.signal} = ${a.value} at ${a.time_s}, not expected`);
    } else if (a.time_s !== e.time_s || a.message !== e.message || a.signal !== e.signal ||
               !close(a.value, e.value)) {
      problems.push(`${e.where}: expected ${e.time_s} ${e.message}.${e.signal} = ${e.value}, ` +
                    `candied decoded ${a.time_s} ${a.message}.${a.signal} = ${a.value}`);
    }
  }
  return problems;
}
