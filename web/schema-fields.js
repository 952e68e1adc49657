// packd dashboard: form fields made from a JSON Schema (the per-input schemas
// of GET /processes/{id}).  schemaField(schema, root, pointer, opts) returns
// {el, get(), set(value)}: get() is the value the fields compose (undefined
// when left at the schema's default), set() fills them from a job's inputs.
// Enums are selects, numbers carry their range, oneOf/anyOf is a selector
// that shows the chosen alternative's fields, arrays have add/remove
// buttons; each field's element names its JSON pointer (data-pointer) so an
// API error about that pointer can be shown beside it (job-form.js).
// Elements are made with app.js's el().
'use strict';

const HUGE = 1e9; // a bound this large is a guard against overflow, not a range worth showing

function deref(s, root) {
  for (let n = 0; s && s.$ref && n < 20; n++) {
    const m = s.$ref.match(/^#\/\$defs\/(.+)$/);
    const target = m && root.$defs ? root.$defs[m[1]] : null;
    if (!target) break;
    const rest = Object.assign({}, s);
    delete rest.$ref;
    s = Object.assign({}, target, rest);
  }
  return s || {};
}

// The unit of a field as a label's span: lengths (a $ref to the schema's
// length, or a name that is one by the job format) follow the job's `unit`
// (class len-unit, which job-form.js keeps up to date), *_s is seconds, *_deg
// degrees; null for none.
function unitSpan(name, raw, opts) {
  const ref = raw.$ref || (raw.items && raw.items.$ref) || '';
  if (/\/length$/.test(ref) || /^(d_min|delta_d|d_max)$/.test(name))
    return el('span', ' [' + (opts.lengthUnit ? opts.lengthUnit() : 'length') + ']', 'unit len-unit');
  if (/_s$/.test(name)) return el('span', ' [s]', 'unit');
  if (/_deg$/.test(name)) return el('span', ' [°]', 'unit');
  return null;
}

function rangeText(s) {
  const lo = s.exclusiveMinimum !== undefined ? '> ' + s.exclusiveMinimum : s.minimum !== undefined ? '≥ ' + s.minimum : '';
  const hiV = s.exclusiveMaximum !== undefined ? s.exclusiveMaximum : s.maximum;
  const hi = hiV === undefined || Math.abs(hiV) >= HUGE ? '' : (s.exclusiveMaximum !== undefined ? '< ' : '≤ ') + hiV;
  return [lo, hi].filter(Boolean).join(', ');
}

// The label line of a field: name, unit, and (small) its help and range.
function labelled(name, s, raw, opts, control) {
  const wrap = el('div', null, 'field');
  const label = el('label');
  label.append(el('span', name, 'fname'));
  const unit = unitSpan(name, raw, opts);
  if (unit) label.append(unit);
  label.append(control);
  wrap.append(label);
  const help = [s.description, rangeText(s), s.default !== undefined ? 'default ' + JSON.stringify(s.default) : '']
    .filter(Boolean).join(' · ');
  if (help && !opts.item) wrap.append(el('small', help, 'help')); // an array's items share its help
  return wrap;
}

function enumField(s, name, raw, opts) {
  const sel = el('select');
  const values = s.enum.slice();
  // the first option sends nothing: the schema's default, or a choice still to make
  sel.append(el('option', s.default !== undefined ? '(default: ' + s.default + ')' : opts.required ? '(choose)' : '(not set)'));
  for (const v of values) sel.append(el('option', v));
  const skip = 1;
  return {
    el: labelled(name, s, raw, opts, sel),
    get: () => (sel.selectedIndex < skip ? undefined : values[sel.selectedIndex - skip]),
    set: (v) => { const i = values.indexOf(v); sel.selectedIndex = i >= 0 ? i + skip : 0; },
  };
}

function booleanField(s, name, raw, opts) {
  return enumField(Object.assign({}, s, { enum: [true, false] }), name, raw, opts);
}

function inputField(s, name, raw, opts) {
  const inp = el('input');
  const numeric = s.type === 'number' || s.type === 'integer';
  inp.type = numeric ? 'number' : 'text';
  if (numeric) {
    inp.step = s.type === 'integer' ? '1' : 'any';
    const lo = s.minimum !== undefined ? s.minimum : s.exclusiveMinimum;
    const hi = s.maximum !== undefined ? s.maximum : s.exclusiveMaximum;
    if (lo !== undefined && Math.abs(lo) < HUGE) inp.min = lo;
    if (hi !== undefined && Math.abs(hi) < HUGE) inp.max = hi;
  }
  if (s.default !== undefined) inp.placeholder = String(s.default);
  return {
    el: labelled(name, s, raw, opts, inp),
    get: () => (inp.value === '' ? undefined : numeric ? Number(inp.value) : inp.value),
    set: (v) => { inp.value = v === undefined || v === null ? '' : String(v); },
  };
}

// A value with no schema the fields can show (a map of names, a bare
// object): edited as JSON.
function jsonField(s, name, raw, opts) {
  const ta = el('textarea');
  ta.rows = 3;
  ta.spellcheck = false;
  return {
    el: labelled(name, s, raw, opts, ta),
    get: () => {
      if (!ta.value.trim()) return undefined;
      try { return JSON.parse(ta.value); } catch (e) { throw Object.assign(new Error(name + ': not JSON (' + e.message + ')'), { pointer: opts.pointer }); }
    },
    set: (v) => { ta.value = v === undefined ? '' : JSON.stringify(v); },
  };
}

function arrayField(s, name, raw, opts, root) {
  const box = el('fieldset', null, 'array');
  const legend = el('legend', name);
  const unit = unitSpan(name, raw, opts);
  if (unit) legend.append(unit);
  box.append(legend);
  if (s.description) box.append(el('small', s.description, 'help'));
  const list = el('div', null, 'items');
  const add = el('button', '+ add', 'add');
  add.type = 'button';
  box.append(list, add);
  let items = [];
  const itemRaw = s.items || {};
  const addItem = (v) => {
    const i = items.length;
    const f = schemaField(itemRaw, root, opts.pointer + '/' + i, { name: name + '[' + i + ']', required: true, lengthUnit: opts.lengthUnit, item: true });
    const row = el('div', null, 'item');
    const del = el('button', '×', 'remove');
    del.type = 'button';
    del.title = 'remove';
    row.append(f.el, del);
    list.append(row);
    const item = { f, row };
    items.push(item);
    del.addEventListener('click', () => {
      const keep = items.filter((x) => x !== item).map((x) => x.f.get());
      setAll(keep);
      box.dispatchEvent(new Event('change', { bubbles: true }));
    });
    if (v !== undefined) f.set(v);
  };
  const setAll = (vs) => {
    list.replaceChildren();
    items = [];
    for (const v of vs) addItem(v);
  };
  add.addEventListener('click', () => { addItem(undefined); box.dispatchEvent(new Event('change', { bubbles: true })); });
  setAll(new Array(opts.required ? s.minItems || 0 : 0).fill(undefined));
  box.dataset.pointer = opts.pointer;
  return {
    el: box,
    get: () => {
      const vs = items.map((x) => x.f.get());
      if (!opts.required && vs.every((v) => v === undefined)) return undefined;
      return vs.map((v) => (v === undefined ? null : v)); // the API names the index left empty
    },
    set: (v) => setAll(Array.isArray(v) ? v : []),
  };
}

// The label of a oneOf/anyOf alternative: its title, the constant its
// `type` member takes, the members it requires, or its JSON type.
function altLabel(a, i) {
  if (a.title) return a.title;
  const p = a.properties || {};
  const c = Object.keys(p).find((k) => p[k] && p[k].const !== undefined);
  if (c) return String(p[c].const);
  if (a.required && a.required.length && !a.properties) return a.required.join(' + ');
  if (a.type) return a.type === 'array' ? 'one per axis' : a.type === 'boolean' ? 'one for all' : a.type;
  return 'choice ' + (i + 1);
}

// Does value v fit alternative a (its type, constants and required members)?
function fits(a, v) {
  const t = Array.isArray(v) ? 'array' : v === null ? 'null' : typeof v;
  if (a.type && !(a.type === t || (a.type === 'integer' && t === 'number'))) return false;
  if (t !== 'object') return !a.type || true;
  for (const [k, p] of Object.entries(a.properties || {}))
    if (p && p.const !== undefined && v[k] !== p.const) return false;
  return (a.required || []).every((k) => k in v);
}

function choiceField(s, name, raw, opts, root) {
  const alts = (s.oneOf || s.anyOf).map((a) => deref(a, root));
  // alternatives that only require members of the object's own properties
  // (domain: box or mesh) show those members and the ones all alternatives share
  const keyed = s.properties && alts.every((a) => !a.properties && !a.type);
  const named = new Set(keyed ? alts.flatMap((a) => a.required || []) : []);
  const schemaOf = (a) => {
    if (!keyed) return a;
    const props = {};
    for (const [k, p] of Object.entries(s.properties)) if (!named.has(k) || (a.required || []).includes(k)) props[k] = p;
    const base = Object.assign({}, s, { properties: props, required: (s.required || []).concat(a.required || []) });
    delete base.oneOf;
    delete base.anyOf;
    return base;
  };
  const box = el('fieldset', null, 'choice');
  box.append(el('legend', name));
  const sel = el('select', null, 'alt');
  if (!opts.required) sel.append(el('option', '(not set)'));
  alts.forEach((a, i) => sel.append(el('option', altLabel(a, i))));
  const skip = opts.required ? 0 : 1;
  const help = el('small', s.description || '', 'help');
  const slot = el('div', null, 'alt-fields');
  const choose = el('label', 'kind ');
  choose.append(sel);
  box.append(choose, help, slot);
  box.dataset.pointer = opts.pointer;
  let current = null;
  const show = () => {
    const i = sel.selectedIndex - skip;
    current = i >= 0 ? schemaField(schemaOf(alts[i]), root, opts.pointer, { name, required: true, lengthUnit: opts.lengthUnit, bare: true }) : null;
    slot.replaceChildren(...(current && current.el ? [current.el] : []));
  };
  sel.addEventListener('change', show);
  sel.selectedIndex = opts.required ? 0 : 0;
  show();
  return {
    el: box,
    get: () => (current ? current.get() : undefined),
    set: (v) => {
      const i = v === undefined ? -1 : alts.findIndex((a) => fits(a, v));
      sel.selectedIndex = i >= 0 ? i + skip : 0;
      show();
      if (current && v !== undefined) current.set(v);
    },
  };
}

// Members named after a value of a sibling enum (pack: `rsa`, `edmd`,
// `tetfill` after `algorithm`) are shown only while that value is chosen.
function optionGroups(props, fields) {
  const groups = [];
  for (const [k, p] of Object.entries(props)) {
    const vals = p.enum || [];
    const members = vals.filter((v) => typeof v === 'string' && v !== k && fields[v]);
    if (members.length) groups.push({ key: k, def: p.default, members });
  }
  return groups;
}

// An object's members, each a field; `inputs` (the top level) gives each
// member its own root (every per-input schema carries its $defs).
function objectField(s, name, raw, opts, root, roots) {
  const props = s.properties || {};
  const required = new Set(s.required || []);
  const fields = {};
  const box = el(opts.bare || opts.top ? 'div' : 'fieldset', null, opts.top ? 'inputs' : 'object');
  if (!opts.bare && !opts.top) box.append(el('legend', name));
  if (!opts.bare && !opts.top && s.description) box.append(el('small', s.description, 'help'));
  let inner = box;
  if (!opts.required && !opts.top && !opts.bare) { // optional: folded until opened or filled
    const det = el('details');
    det.append(el('summary', 'options'));
    box.append(det);
    inner = det;
  }
  for (const [k, p] of Object.entries(props)) {
    const f = schemaField(p, roots ? roots[k] : root, opts.pointer + '/' + k,
      { name: k, required: required.has(k), lengthUnit: opts.lengthUnit });
    fields[k] = f;
    if (f.el) { f.el.dataset.member = k; inner.append(f.el); }
  }
  const groups = optionGroups(props, fields);
  const shown = (k) => groups.every((g) => !g.members.includes(k) || (fields[g.key].get() ?? g.def) === k);
  const refresh = () => { for (const k of Object.keys(fields)) if (fields[k].el) fields[k].el.hidden = !shown(k); };
  if (groups.length) box.addEventListener('change', refresh);
  refresh();
  box.dataset.pointer = opts.pointer;
  return {
    el: box,
    fields,
    get: () => {
      const o = {};
      for (const [k, f] of Object.entries(fields)) {
        if (!shown(k)) continue;
        const v = f.get();
        if (v !== undefined) o[k] = v;
      }
      return !opts.required && !opts.top && !Object.keys(o).length ? undefined : o;
    },
    set: (v) => {
      const o = v && typeof v === 'object' ? v : {};
      for (const [k, f] of Object.entries(fields)) f.set(o[k]);
      if (inner.tagName === 'DETAILS') inner.open = Object.keys(o).length > 0;
      refresh();
    },
  };
}

function schemaField(raw, root, pointer, opts) {
  const s = deref(raw, root);
  const name = opts.name || '';
  const o = Object.assign({}, opts, { pointer });
  let f;
  if (s.const !== undefined) return { el: null, get: () => s.const, set: () => {} };
  if (s.oneOf || s.anyOf) f = choiceField(s, name, raw, o, root);
  else if (s.enum) f = enumField(s, name, raw, o);
  else if (s.type === 'boolean') f = booleanField(s, name, raw, o);
  else if (['number', 'integer', 'string'].includes(s.type)) f = inputField(s, name, raw, o);
  else if (s.type === 'array' && s.items) f = arrayField(s, name, raw, o, root);
  else if (s.properties || (s.type === 'object' && opts.roots)) f = objectField(s, name, raw, o, root, opts.roots);
  else f = jsonField(s, name, raw, o);
  if (f.el && !f.el.dataset.pointer) f.el.dataset.pointer = pointer;
  return f;
}
