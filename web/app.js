// packd dashboard: the job list with live progress (its filters and pages:
// list-filters.js) and the queue's state, and a job page (its summary:
// summary-groups.js); the job form is job-form.js.  It reads the API as any client does; job data
// enters the page only as text (textContent), never as markup.
'use strict';

const $ = (id) => document.getElementById(id);
const token = () => localStorage.getItem('packd.token') || '';
const FINAL = ['successful', 'failed', 'dismissed'];
const MAX_STREAMS = 4; // a browser keeps ~6 connections per host

function headers(extra) {
  const h = Object.assign({}, extra || {});
  if (token()) h.Authorization = 'Bearer ' + token();
  return h;
}

function showError(text) {
  const e = $('error');
  e.textContent = text || '';
  e.hidden = !text;
}

async function api(path, opts) {
  const o = Object.assign({}, opts || {});
  o.headers = headers(Object.assign({ Accept: 'application/json' }, o.headers || {}));
  const r = await fetch(path, o);
  const body = await r.json().catch(() => ({}));
  if (!r.ok) {
    const msg = (body.title || r.statusText) + (body.detail ? ': ' + body.detail : '');
    throw Object.assign(new Error(r.status + ' ' + msg), { status: r.status, body });
  }
  return body;
}

// An RFC 3339 time of the API in the browser's time zone, which it names
// ("7 Dec 2026, 22:14:05 GMT+5:30"); '' when absent.
function localTime(iso) {
  const t = iso ? new Date(iso) : null;
  if (!t || isNaN(t)) return '';
  return t.toLocaleString(undefined, {
    year: 'numeric', month: 'short', day: 'numeric', hour: '2-digit', minute: '2-digit',
    second: '2-digit', timeZoneName: 'short',
  });
}

function duration(s) {
  const t = Math.round(s);
  return t < 60 ? t + ' s' : Math.floor(t / 60) + ' min ' + String(t % 60).padStart(2, '0') + ' s';
}

// The line of a progress event: its stage, φ (Δd while a shell grows), the
// time elapsed and left
// (the stage's own estimate, else a linear one from its fraction)
function progressLine(d) {
  let line = d.stage + (d.delta_d > 0 ? ', Δd = ' + Number(d.delta_d).toPrecision(4) // shell growth
    : d.phi > 0 ? ', φ = ' + Number(d.phi).toFixed(4) : '');
  if (typeof d.elapsed_s === 'number') {
    line += ', ' + duration(d.elapsed_s) + ' elapsed';
    const eta = typeof d.eta_s === 'number' && d.eta_s >= 0 ? d.eta_s
      : d.fraction >= 0.02 && d.fraction < 1 ? d.elapsed_s * (1 - d.fraction) / d.fraction : -1;
    if (eta >= 0) line += ', about ' + duration(eta) + ' left';
  }
  return line;
}

function el(tag, text, cls) {
  const e = document.createElement(tag);
  if (text !== undefined && text !== null) e.textContent = String(text);
  if (cls) e.className = cls;
  return e;
}

// --- live progress: the job's event stream (text/event-stream over fetch, so
// the token goes in a header; EventSource cannot send one)
const streams = new Map(); // jobID -> AbortController
let view = 0; // moves on every route(): work begun for an earlier view drops its results

// Stream a job's events to onEvent; onEnd(final) once the stream is over,
// final saying whether a final status came through it.
function stream(id, onEvent, onEnd) {
  if (streams.has(id) || streams.size >= MAX_STREAMS) return;
  const ctl = new AbortController();
  streams.set(id, ctl);
  let final = false;
  (async () => {
    try {
      const r = await fetch('jobs/' + encodeURIComponent(id) + '/events',
        { headers: headers({ Accept: 'text/event-stream' }), signal: ctl.signal });
      if (!r.ok || !r.body) return;
      const reader = r.body.pipeThrough(new TextDecoderStream()).getReader();
      let buf = '';
      for (;;) {
        const { value, done } = await reader.read();
        if (done) break;
        buf += value;
        let cut;
        while ((cut = buf.indexOf('\n\n')) >= 0) {
          const block = buf.slice(0, cut);
          buf = buf.slice(cut + 2);
          let kind = 'message', data = '';
          for (const line of block.split('\n')) {
            if (line.startsWith('event:')) kind = line.slice(6).trim();
            else if (line.startsWith('data:')) data += line.slice(5).trim();
          }
          if (!data) continue;
          let d;
          try { d = JSON.parse(data); } catch (e) { continue; /* not JSON: ignore */ }
          final = final || FINAL.includes(d.status);
          onEvent(kind, d);
        }
      }
    } catch (e) { /* aborted or the connection dropped */ }
    finally {
      if (streams.get(id) === ctl) streams.delete(id);
      if (!ctl.signal.aborted && onEnd) onEnd(final);
    }
  })();
}

function stopStreams() {
  for (const ctl of streams.values()) ctl.abort();
  streams.clear();
}

// --- the job list
const rows = new Map(); // jobID -> {tr, status, bar, msg}

function setProgress(row, p) {
  if (typeof p === 'number') {
    row.bar.value = p;
    row.pct.textContent = ' ' + p + ' %';
  }
}

function setStatus(row, st) {
  row.status.textContent = st;
  row.status.className = 'status st-' + st;
  row.tr.dataset.status = st;
}

function onListEvent(id) {
  return (kind, d) => {
    const row = rows.get(id);
    if (!row) return;
    if (d.status) setStatus(row, d.status);
    if (typeof d.message === 'string') row.msg.textContent = d.message;
    if (kind === 'progress' && d.stage) row.msg.textContent = progressLine(d);
    setProgress(row, d.progress);
  };
}

function jobRow(j) {
  let row = rows.get(j.jobID);
  if (!row) {
    const tr = el('tr');
    tr.dataset.job = j.jobID;
    const link = el('a', j.jobID.slice(0, 8));
    link.href = '#/jobs/' + encodeURIComponent(j.jobID);
    link.title = j.jobID;
    const idc = el('td');
    idc.appendChild(el('code')).appendChild(link);
    const bar = el('progress');
    bar.max = 100;
    bar.value = 0;
    bar.className = 'job-progress';
    const barc = el('td');
    const pct = el('span', '', 'pct');
    barc.append(bar, pct);
    row = { tr, status: el('td'), bar, pct, msg: el('td') };
    const created = el('td', localTime(j.created), 'created');
    created.title = j.created || '';
    tr.append(idc, el('td', j.processID), row.status, barc, row.msg, created);
    rows.set(j.jobID, row);
  }
  setStatus(row, j.status);
  row.msg.textContent = j.message || '';
  setProgress(row, j.status === 'successful' ? 100 : j.progress);
  if (!FINAL.includes(j.status)) stream(j.jobID, onListEvent(j.jobID));
  return row;
}

let listAsked = 0, listShown = 0; // list refreshes begun, and the newest one shown
let processesListed = false;

async function refreshList() {
  const v = view, n = ++listAsked, p = listParams();
  try {
    const doc = await api(listQuery(p));
    // the page moved on while the list was asked for, or a newer answer is shown
    if (v !== view || n < listShown) return;
    listShown = n;
    const tbody = $('jobs').tBodies[0];
    const seen = new Set();
    for (const j of doc.jobs || []) {
      seen.add(j.jobID);
      tbody.appendChild(jobRow(j).tr); // in the list's order (newest first)
    }
    for (const [id, row] of rows) {
      if (seen.has(id)) continue;
      row.tr.remove();
      rows.delete(id);
      const ctl = streams.get(id); // a row gone from the list (filtered out) needs no stream
      if (ctl) { ctl.abort(); streams.delete(id); }
    }
    showPaging(p, doc);
    showError('');
  } catch (e) {
    showError('Job list: ' + e.message + (token() ? '' : ' (auth on? enter a token above)'));
    return;
  }
  // asked once the list answered: with auth on they need the token too
  refreshQueue(v);
  refreshRVEs(v);
  if (!processesListed) {
    api('processes').then((d) => { processesListed = true; fillProcesses(d); }, () => {});
    offerOwnerFilter();
  }
}

// Jobs waiting and running, workers busy of the maximum, and where they run.
async function refreshQueue(v) {
  try {
    const q = await api('dashboard/queue');
    if (v !== view) return;
    for (const k of ['accepted', 'running', 'workers_busy', 'workers_max', 'executor']) $('q-' + k).textContent = q[k];
  } catch (e) { showError('Queue: ' + e.message); }
}

// --- the job page
let pageJob = null;

function fileURL(id, output) {
  return 'jobs/' + encodeURIComponent(id) + '/results/' + output;
}

// With a token, pictures and files come through fetch (an <img> or a link
// cannot send the header) and are shown from blob: URLs.
async function blobURL(url) {
  const r = await fetch(url, { headers: headers() });
  if (!r.ok) throw new Error(r.status + ' ' + r.statusText);
  return URL.createObjectURL(await r.blob());
}

function picture(id, output, title) {
  const fig = el('figure');
  const img = el('img');
  img.alt = title;
  img.dataset.output = output;
  fig.append(img, el('figcaption', title));
  $('pictures').appendChild(fig);
  if (token()) blobURL(fileURL(id, output)).then((u) => { img.src = u; }, (e) => showError(output + ': ' + e.message));
  else img.src = fileURL(id, output);
}

function download(id, output, name, title) {
  const li = el('li');
  const a = el('a', title);
  a.href = fileURL(id, output);
  a.download = name;
  a.dataset.output = output;
  if (token()) {
    a.addEventListener('click', async (ev) => {
      if (a.href.startsWith('blob:')) return;
      ev.preventDefault();
      try { a.href = await blobURL(fileURL(id, output)); a.click(); } catch (e) { showError(title + ': ' + e.message); }
    });
  }
  li.append(a, el('span', ' (' + name + ')'));
  $('downloads').appendChild(li);
}

// The summary grouped, with the units of its figures (summary-groups.js).
async function loadSummary(id) {
  try {
    const [sum, u] = await Promise.all([api(fileURL(id, 'summary')),
      api('dashboard/jobs/' + encodeURIComponent(id) + '/units').catch(() => ({ units: {} }))]);
    if (pageJob === id) showSummary($('summary'), sum, u.units || {});
  } catch (e) { showError('Summary: ' + e.message); }
}

// A statusInfo document or an event of the job's stream: progress events
// carry no status, so the last known one stays.
function showJobStatus(s, kind) {
  if (s.status) {
    $('job-status').textContent = s.status;
    $('job-status').className = 'status st-' + s.status;
    $('cancel').hidden = !['accepted', 'running'].includes(s.status);
  }
  const p = s.status === 'successful' ? 100 : s.progress;
  if (typeof p === 'number') { $('job-progress').value = p; $('job-percent').textContent = p + ' %'; }
  if (typeof s.message === 'string') $('job-message').textContent = s.message;
  else if (kind === 'progress' && s.stage) $('job-message').textContent = progressLine(s);
  if (s.created) {
    $('job-times').textContent = ['created', 'started', 'finished']
      .filter((k) => s[k]).map((k) => k + ' ' + localTime(s[k])).join(' · ');
  }
}

async function cancelJob() {
  const id = pageJob;
  try {
    showJobStatus(await api('jobs/' + encodeURIComponent(id), { method: 'DELETE' }));
  } catch (e) { showError('Cancel: ' + e.message); }
}

// A failed job: why it stopped, its summary, and its partial result file
// when the worker left one (the statusInfo's partial-result link).
async function showFailed(id, s) {
  $('job-reason').textContent = 'Why it failed: ' + (s.failure || s.message || 'no reason recorded');
  $('job-reason').hidden = false;
  if ((s.links || []).some((l) => l.rel === 'partial-result'))
    download(id, 'result', id + '.partial.h5', 'partial HDF5 result (as far as the job got)');
  await loadSummary(id);
}

async function showJob(id) {
  const v = view;
  pageJob = id;
  $('job-id').textContent = id;
  for (const k of ['pictures', 'downloads', 'job-message', 'job-percent', 'job-inputs', 'job-times', 'job-reason']) $(k).replaceChildren();
  $('job-reason').hidden = true;
  $('cancel').hidden = true;
  $('summary').replaceChildren();
  let s;
  try { s = await api('jobs/' + encodeURIComponent(id)); } catch (e) { showError('Job: ' + e.message); return; }
  if (v !== view) return;
  showJobStatus(s);
  if (s.status === 'dismissed') $('job-inputs').textContent = '(removed with the job)';
  else {
    api('dashboard/jobs/' + encodeURIComponent(id) + '/inputs').then(
      (j) => { $('job-inputs').textContent = JSON.stringify(j.inputs, null, 2); },
      () => { $('job-inputs').textContent = '(not available)'; });
  }
  if (!FINAL.includes(s.status)) {
    const here = () => v === view && pageJob === id;
    stream(id, (kind, d) => {
      if (!here()) return;
      showJobStatus(d, kind);
      if (d.status && FINAL.includes(d.status)) showJob(id);
    }, (final) => { // a stream that broke off: ask again shortly
      if (!final && here()) setTimeout(() => { if (here()) showJob(id); }, 2000);
    });
    return;
  }
  if (s.status === 'failed') return showFailed(id, s);
  if (s.status !== 'successful') return;
  let res;
  try { res = await api('jobs/' + encodeURIComponent(id) + '/results'); } catch (e) { showError('Results: ' + e.message); return; }
  // every output the results document lists: PNG pictures and plots shown,
  // every file offered for download (the HDF5 result and its XDMF first)
  const outs = Object.keys(res).filter((k) => res[k] && res[k].href);
  for (const k of outs)
    if (res[k].type === 'image/png') picture(id, k, res[k].title || k);
  const order = (k) => (k === 'result' ? 0 : k === 'xdmf' ? 1 : 2);
  for (const k of outs.sort((a, b) => order(a) - order(b))) {
    if (k === 'result') download(id, k, id + '.h5', 'HDF5 result (H5MD)');
    else if (k === 'xdmf') download(id, k, id + '.xdmf', 'XDMF for ParaView (save it next to the .h5 file)');
    else download(id, k, id + '-' + k, (res[k].title || k) + ' (' + k.split('.').pop().toUpperCase() + ')');
  }
  await loadSummary(id);
}

// --- routing: #/ the list (#/?status=…&process=…&page=…: list-filters.js), #/jobs/ID a job
let listTimer = null;

function route() {
  view++;
  stopStreams();
  rows.clear();
  $('jobs').tBodies[0].replaceChildren();
  clearInterval(listTimer);
  const m = location.hash.match(/^#\/jobs\/([^/]+)$/);
  $('list-view').hidden = !!m;
  $('job-view').hidden = !m;
  if (m) {
    showJob(decodeURIComponent(m[1]));
  } else {
    $('back').href = location.hash || '#/'; // a job page leads back to the list it was opened from
    pageJob = null;
    showFilters(listParams());
    $('range').textContent = '';
    refreshList();
    listTimer = setInterval(refreshList, 5000);
  }
}

document.addEventListener('DOMContentLoaded', () => {
  $('token').value = token();
  $('token-form').addEventListener('submit', (ev) => {
    ev.preventDefault();
    localStorage.setItem('packd.token', $('token').value.trim());
    processesListed = false; // the owner filter is an admin's
    loadForm();
    route();
  });
  $('cancel').addEventListener('click', cancelJob);
  window.addEventListener('hashchange', route);
  route();
});
