// Loads a DBC file with candied and reports, on standard error, every line it cannot parse and
// every definition it parsed but dropped (candied reads line by line and skips what it does not
// understand, so the counts of the file's definitions and of the loaded ones are compared).

function count(text, pattern) {
  return text.split('\n').filter((line) => pattern.test(line)).length;
}

/// How many items have f(item) truthy.
function countIf(iterable, f) {
  let total = 0;
  for (const item of iterable) total += f(item) ? 1 : 0;
  return total;
}

function parseErrors(dbc, path, lines) {
  const problems = [];
  for (const [lineNumber, errors] of dbc.errors) {
    for (const error of errors) {
      const column = (error.pos?.offset ?? 0) + 1;
      problems.push(`${path}:${lineNumber}:${column}: candied cannot parse: ` +
                    `${lines[lineNumber - 1]}`);
    }
  }
  return problems;
}

function droppedDefinitions(data, path, text) {
  const messages = [...data.messages.values()];
  const signals = messages.flatMap((m) => [...m.signals.values()]);
  const attributeValues = messages.flatMap((m) => [...m.attributes.values()]);
  const checks = [
    ['messages (BO_)', count(text, /^BO_ /), messages.length],
    ['distinct message ids', count(text, /^BO_ /), new Set(messages.map((m) => m.id)).size],
    ['signals (SG_)', count(text, /^\s*SG_ /), signals.length],
    ['message comments (CM_ BO_)', count(text, /^CM_ BO_ /),
     countIf(messages, (m) => m.description)],
    ['signal comments (CM_ SG_)', count(text, /^CM_ SG_ /), countIf(signals, (s) => s.description)],
    ['value tables (VAL_)', count(text, /^VAL_ \d/), countIf(signals, (s) => s.valueTable)],
    ['message attribute values (BA_ BO_)', count(text, /^BA_ "\w+" BO_ /),
     countIf(attributeValues, (a) => a.value !== null)],
  ];
  const problems = checks.filter(([, inFile, loaded]) => inFile !== loaded).map(
      ([what, inFile, loaded]) => `${path}: ${inFile} ${what} in the file, ${loaded} loaded`);
  const nodes = new Set(data.nodes.keys());
  for (const m of messages) {
    const receivers = [...m.signals.values()].flatMap((s) => s.receivingNodes);
    for (const node of new Set([m.sendingNode, ...receivers])) {
      if (!nodes.has(node)) problems.push(`${path}: ${m.name}: node ${node} is not in BU_`);
    }
  }
  return problems;
}

/// The loaded data, or null after reporting why the file did not load cleanly.
export function loadDbc(dbc, path, text) {
  const data = dbc.load(text);
  const lines = text.split('\n');
  const problems = [...parseErrors(dbc, path, lines), ...droppedDefinitions(data, path, text)];
  for (const problem of problems) console.error(`decode_log: ${problem}`);
  if (problems.length > 0) {
    console.error(`decode_log: ${path}: ${problems.length} problems: candied does not load it ` +
                  'cleanly');
    return null;
  }
  return data;
}
