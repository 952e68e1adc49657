// packd dashboard: a job's summary in groups, each figure with its unit
// (GET /dashboard/jobs/{id}/units).  A pack job's groups say what was asked,
// what was achieved, the audit of the result and the model; another
// process's members are grouped by their key's first part.
'use strict';

// [id, title, has(key)]: the first group whose test a key passes holds it
const PACK_GROUPS = [
  ['asked', 'What was asked', (k) => /^(process|count_requested|phi_target_\w+|d_min|delta_d|algorithm)$/.test(k) || /\.max_failed_draws$/.test(k)],
  ['audit', 'The audit', (k) => /^(smallest_gap|smallest_wall_gap|pairs_below_delta_d|grains_below_wall_gap|result_digest)$/.test(k) || k.startsWith('timing.')],
  ['model', 'The model', (k) => k.startsWith('model.')],
  ['achieved', 'What was achieved', () => true],
];
const PACK_ORDER = ['asked', 'achieved', 'audit', 'model'];

// [key, value] of every member, nested objects flattened with '.'.
function flatten(obj, prefix, out) {
  for (const [k, v] of Object.entries(obj || {})) {
    const key = prefix ? prefix + '.' + k : k;
    if (v !== null && typeof v === 'object' && !Array.isArray(v)) flatten(v, key, out);
    else out.push([key, v]);
  }
  return out;
}

function shownValue(v) {
  if (typeof v === 'number' && !Number.isInteger(v)) return String(Number(v.toPrecision(6)));
  if (typeof v === 'boolean' || typeof v === 'number') return String(v);
  return typeof v === 'string' ? v : JSON.stringify(v);
}

// An array of objects (a pack job's size classes) as a table of its own.
function recordsTable(rows) {
  const t = el('table', null, 'records');
  const cols = [...new Set(rows.flatMap((r) => Object.keys(r)))];
  const head = el('tr');
  for (const c of cols) head.append(el('th', c));
  t.append(head);
  for (const r of rows) {
    const tr = el('tr');
    for (const c of cols) tr.append(el('td', r[c] === undefined ? '' : shownValue(r[c])));
    t.append(tr);
  }
  return t;
}

function valueCell(v, unit) {
  const td = el('td');
  if (Array.isArray(v) && v.length && v.every((x) => x && typeof x === 'object')) td.append(recordsTable(v));
  else {
    td.append(el('span', shownValue(v), 'value'));
    if (unit) td.append(el('span', ' ' + unit, 'unit'));
  }
  return td;
}

// [[id, title, [[key, value]…]]…] of the summary, empty groups left out.
function summaryGroups(summary) {
  const members = flatten(summary, '', []);
  if (summary.process === 'pack') {
    const groups = PACK_GROUPS.map(([id, title]) => [id, title, []]);
    for (const m of members) groups[PACK_GROUPS.findIndex(([, , has]) => has(m[0]))][2].push(m);
    return PACK_ORDER.map((id) => groups.find((g) => g[0] === id)).filter((g) => g[2].length);
  }
  const byPart = new Map();
  for (const m of members) {
    const part = m[0].includes('.') ? m[0].split('.')[0] : 'general';
    if (!byPart.has(part)) byPart.set(part, []);
    byPart.get(part).push(m);
  }
  return [...byPart].map(([part, ms]) => [part, part, ms]);
}

// Show the summary in box (a div), with units where the API knows one.
function showSummary(box, summary, units) {
  box.replaceChildren();
  for (const [id, title, members] of summaryGroups(summary)) {
    const sec = el('section', null, 'sgroup');
    sec.dataset.group = id;
    sec.append(el('h4', title));
    const t = el('table', null, 'kv');
    for (const [k, v] of members) {
      const tr = el('tr');
      tr.dataset.key = k;
      tr.append(el('th', k), valueCell(v, units[k]));
      t.append(tr);
    }
    sec.append(t);
    box.append(sec);
  }
}
