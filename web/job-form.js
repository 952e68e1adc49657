// packd dashboard: the job form.  Its fields are made from the chosen
// process's input schemas (GET /processes/{id}: schema-fields.js); an
// example fills them; the JSON below mirrors them both ways (an edit there
// fills the fields).  Submit posts the composed inputs; the API's 4xx
// errors are shown at the field their pointer names.
'use strict';

let examples = [];
let packResults = []; // successful pack jobs: the RVEs a homogenize job can take
let form = null; // {process, field}: the fields of the process shown
let formAsked = 0;

const lengthUnit = () => {
  const u = form && form.field.fields.unit ? form.field.fields.unit.get() : undefined;
  return u || 'mm';
};

const processDocs = new Map(); // GET /processes/{id}, read once

// The fields of process id (afresh: even when they are shown), built at
// once when its description has been read before.
async function buildForm(id, afresh) {
  if (form && form.process === id && !afresh) return;
  const n = ++formAsked;
  const doc = processDocs.get(id) || await api('processes/' + encodeURIComponent(id));
  processDocs.set(id, doc);
  if (n !== formAsked) return;
  const inputs = doc.inputs || {};
  const props = {}, roots = {}, required = [];
  for (const [k, d] of Object.entries(inputs)) {
    props[k] = d.schema || {};
    roots[k] = d.schema || {};
    if ((d.minOccurs || 0) >= 1) required.push(k);
  }
  const field = schemaField({ type: 'object', properties: props, required }, {}, '',
    { top: true, required: true, roots, lengthUnit });
  form = { process: id, field };
  $('process-help').textContent = doc.description || '';
  $('form-fields').replaceChildren(field.el);
  $('process').value = id;
  $('rve-pick').hidden = !inputs.rve;
  formChanged();
}

// The examples (public) and, once the API answers (with auth on: a token),
// the processes and the first one's fields.
async function loadForm() {
  try {
    examples = (await api('dashboard/examples')).examples || [];
  } catch (e) { showError('Examples: ' + e.message); }
  const exs = $('example');
  exs.replaceChildren(el('option', '(none: the schema\'s defaults)'));
  exs.options[0].value = '';
  examples.forEach((e, i) => {
    const o = el('option', e.name.replace(/\.json$/, '') + ' (' + e.process + ')');
    o.value = String(i);
    exs.appendChild(o);
  });
  try {
    const procs = await api('processes');
    const sel = $('process');
    sel.replaceChildren();
    for (const p of procs.processes || []) {
      const o = el('option', p.id + (p.title ? ' — ' + p.title : ''));
      o.value = p.id;
      sel.appendChild(o);
    }
    await buildForm(form ? form.process : sel.value);
    if (form) sel.value = form.process;
  } catch (e) { showError('Job form: ' + e.message + (token() ? '' : ' (auth on? enter a token above)')); }
}

async function pickExample() {
  const ex = $('example').value === '' ? null : examples[Number($('example').value)];
  $('example-comment').textContent = ex ? ex.comment || '' : '';
  if (!ex) { // none: the process's fields as the schema leaves them
    try { await buildForm(form ? form.process : $('process').value, true); } catch (e) { showError('Job form: ' + e.message); }
    return;
  }
  try { await buildForm(ex.process); } catch (e) { showError('Job form: ' + e.message); return; }
  form.field.set(ex.inputs);
  formChanged();
  $('inputs').value = JSON.stringify(ex.inputs, null, 2); // as the example says it
  fillRVE();
  if (ex.inputs.rve && listShown) refreshRVEs(view); // once the API has answered (a token)
}

// The fields changed: the JSON shows what they compose, the length units follow `unit`.
function formChanged() {
  clearFieldErrors();
  for (const u of document.querySelectorAll('#form-fields .len-unit')) u.textContent = ' [' + lengthUnit() + ']';
  try { $('inputs').value = JSON.stringify(form.field.get(), null, 2); } catch (e) { /* shown on submit */ }
}

// The JSON edited: the fields show it (what they cannot show stays in the JSON).
function jsonEdited() {
  let v;
  try { v = JSON.parse($('inputs').value); } catch (e) { return; }
  if (form && v && typeof v === 'object') form.field.set(v);
}

// The RVEs a homogenize job can take, asked only while its form is shown.
async function refreshRVEs(v) {
  if (!form || $('rve-pick').hidden) return;
  try {
    const doc = await api('jobs?processID=pack&status=successful&limit=50');
    if (v !== view) return;
    packResults = doc.jobs || [];
    fillRVE();
  } catch (e) { /* the list shows the API's error */ }
}

// A homogenize example names an RVE file of its own folder; here it takes
// the result of one of the user's finished pack jobs instead.
function fillRVE() {
  const wants = !$('rve-pick').hidden;
  const sel = $('rve');
  const keep = sel.value;
  sel.replaceChildren(el('option', wants && !packResults.length ? '(first run a pack job)' : '(as in the form)'));
  sel.options[0].value = '';
  for (const j of packResults) {
    const o = el('option', j.jobID.slice(0, 8) + ' ' + localTime(j.created));
    o.value = '/jobs/' + j.jobID + '/results/result';
    sel.appendChild(o);
  }
  sel.value = keep;
  if (sel.value !== keep || !keep) sel.selectedIndex = packResults.length ? 1 : 0;
}

function clearFieldErrors() {
  const shown = document.querySelectorAll('#form-fields .field-error');
  if (shown.length) showError(''); // the 4xx they came with
  for (const e of shown) e.remove();
  $('form-errors').hidden = true;
}

// Each error of a 4xx at the deepest visible field its pointer lies in
// (/inputs/domain/box/size/0 → the size's first item); the rest below the form.
function showFieldErrors(errors) {
  const rest = [];
  for (const er of errors) {
    const ptr = String(er.pointer || '').replace(/^\/inputs/, '');
    let best = null;
    for (const f of document.querySelectorAll('#form-fields [data-pointer]')) {
      const p = f.dataset.pointer;
      if (f.offsetParent === null && !f.closest('details:not([open])')) continue; // hidden alternative
      if ((ptr === p || ptr.startsWith(p + '/') || p === '') && (!best || p.length > best.dataset.pointer.length)) best = f;
    }
    const text = (er.message || er.rule || 'invalid') + (er.rule ? ' (' + er.rule + ')' : '');
    if (!best || best.dataset.pointer === '') { rest.push(ptr + ': ' + text); continue; }
    for (let d = best.closest('details'); d; d = d.parentElement.closest('details')) d.open = true;
    const p = el('p', text, 'field-error');
    p.dataset.pointer = ptr;
    best.appendChild(p);
  }
  $('form-errors').textContent = rest.join('; ');
  $('form-errors').hidden = !rest.length;
}

async function submitForm(ev) {
  ev.preventDefault();
  if (!form) return;
  clearFieldErrors();
  let inputs;
  try { inputs = JSON.parse($('inputs').value); } catch (e) { showError('Inputs: ' + e.message); return; }
  if (inputs.rve && $('rve').value && !$('rve-pick').hidden) inputs.rve = { href: $('rve').value };
  try {
    const doc = await api('processes/' + encodeURIComponent(form.process) + '/execution', {
      method: 'POST', headers: { 'Content-Type': 'application/json' },
      body: JSON.stringify({ inputs }),
    });
    const out = $('submitted');
    out.replaceChildren('submitted ');
    const a = el('a', doc.jobID);
    a.href = '#/jobs/' + encodeURIComponent(doc.jobID);
    out.appendChild(a);
    showError('');
    await refreshList();
  } catch (e) {
    if (e.body && Array.isArray(e.body.errors)) { showFieldErrors(e.body.errors); showError('Submit: ' + e.message); }
    else showError('Submit: ' + e.message);
  }
}

document.addEventListener('DOMContentLoaded', () => {
  $('submit-form').addEventListener('submit', submitForm);
  $('example').addEventListener('change', pickExample);
  $('process').addEventListener('change', () => { $('example').value = ''; buildForm($('process').value).catch((e) => showError('Job form: ' + e.message)); });
  $('form-fields').addEventListener('change', formChanged);
  $('form-fields').addEventListener('input', formChanged);
  $('inputs').addEventListener('input', jsonEdited);
  loadForm();
});
