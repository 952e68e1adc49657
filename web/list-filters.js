// packd dashboard: the job list's filters and pages.  They live in the URL's
// hash (#/?status=running,accepted&process=pack&owner=alice&page=2&limit=50), so a reload
// or a shared link shows the same list; the API does the filtering and the
// paging (GET /jobs: status, processID, owner, limit, offset, numberMatched
// and the next/prev links).  The owner filter is an admin's (GET
// /dashboard/me says who is one).  app.js reads them on every route().
'use strict';

const PAGE_SIZE = 50;
const STATUSES = ['accepted', 'running', 'successful', 'failed', 'dismissed'];

// The list's parameters from the hash; an absent or unreadable number is its default.
function listParams() {
  const m = location.hash.match(/^#\/\?(.*)$/);
  const q = new URLSearchParams(m ? m[1] : '');
  const values = (k) => (q.get(k) || '').split(',').map((s) => s.trim()).filter(Boolean);
  const count = (k, def) => {
    const n = Number(q.get(k));
    return Number.isInteger(n) && n >= 1 ? n : def;
  };
  // a limit above the API's maximum (route_job_list.c) would page past what it lists
  return { status: values('status'), process: values('process'), owner: (q.get('owner') || '').trim(), page: count('page', 1), limit: Math.min(count('limit', PAGE_SIZE), 10000) };
}

function listHash(p) {
  const parts = [];
  const add = (k, v) => parts.push(k + '=' + v);
  if (p.status.length) add('status', p.status.map(encodeURIComponent).join(','));
  if (p.process.length) add('process', p.process.map(encodeURIComponent).join(','));
  if (p.owner) add('owner', encodeURIComponent(p.owner));
  if (p.page > 1) add('page', p.page);
  if (p.limit !== PAGE_SIZE) add('limit', p.limit);
  return '#/' + (parts.length ? '?' + parts.join('&') : '');
}

// The GET /jobs request of a page (a bad value in the hash is the API's 400 to show).
function listQuery(p) {
  let q = 'jobs?limit=' + p.limit + '&offset=' + (p.page - 1) * p.limit;
  if (p.status.length) q += '&status=' + p.status.map(encodeURIComponent).join(',');
  if (p.process.length) q += '&processID=' + p.process.map(encodeURIComponent).join(',');
  if (p.owner) q += '&owner=' + encodeURIComponent(p.owner);
  return q;
}

// The controls show the hash's filters (the process menu gains an entry
// for a value it does not list, e.g. from a shared link).
function showFilters(p) {
  for (const box of document.querySelectorAll('#filters input[name="status"]'))
    box.checked = p.status.includes(box.value);
  const sel = document.getElementById('f-process');
  const want = p.process.join(',');
  if (want && ![...sel.options].some((o) => o.value === want)) {
    const o = document.createElement('option');
    o.value = o.textContent = want;
    sel.appendChild(o);
  }
  sel.value = want;
  $('f-owner').value = p.owner;
  if (p.owner) $('f-owner-pick').hidden = false; // a shared link's filter stays visible
}

// The owner filter for an admin, its list offering the admin's own name.
async function offerOwnerFilter() {
  try {
    const me = await api('dashboard/me');
    $('f-owner-pick').hidden = !me.admin && !listParams().owner;
    const list = $('f-owners');
    if (![...list.options].some((o) => o.value === me.owner)) {
      const o = document.createElement('option');
      o.value = me.owner;
      list.appendChild(o);
    }
  } catch (e) { /* the list shows the API's error */ }
}

function fillProcesses(doc) {
  const sel = document.getElementById('f-process');
  for (const pr of doc.processes || []) {
    if ([...sel.options].some((o) => o.value === pr.id)) continue;
    const o = document.createElement('option');
    o.value = o.textContent = pr.id;
    sel.appendChild(o);
  }
  showFilters(listParams());
}

// "jobs 51–100 of 137" and the buttons the API's next/prev links allow.
function showPaging(p, doc) {
  const n = (doc.jobs || []).length, first = (p.page - 1) * p.limit + 1;
  const filtered = p.status.length || p.process.length || p.owner;
  let text;
  if (n) text = 'jobs ' + first + '–' + (first + n - 1) + (typeof doc.numberMatched === 'number' ? ' of ' + doc.numberMatched : '');
  else if (p.page > 1) text = 'no jobs on page ' + p.page;
  else text = filtered ? 'no jobs match the filters' : 'no jobs yet';
  document.getElementById('range').textContent = text;
  const rel = (r) => (doc.links || []).some((l) => l.rel === r);
  document.getElementById('prev').disabled = !rel('prev');
  document.getElementById('next').disabled = !rel('next');
}

function goToList(change) {
  location.hash = listHash(Object.assign(listParams(), change));
}

document.addEventListener('DOMContentLoaded', () => {
  const boxes = document.getElementById('f-status');
  for (const st of STATUSES) {
    const box = document.createElement('input');
    box.type = 'checkbox';
    box.name = 'status';
    box.value = st;
    const label = document.createElement('label');
    label.append(box, ' ' + st);
    boxes.appendChild(label);
  }
  const apply = () => {
    const status = [...document.querySelectorAll('#filters input[name="status"]:checked')].map((b) => b.value);
    const process = document.getElementById('f-process').value;
    const owner = document.getElementById('f-owner').value.trim();
    goToList({ status, process: process ? process.split(',') : [], owner, page: 1 });
  };
  document.getElementById('filters').addEventListener('change', apply);
  document.getElementById('filters').addEventListener('submit', (ev) => { ev.preventDefault(); apply(); });
  document.getElementById('prev').addEventListener('click', () => goToList({ page: Math.max(1, listParams().page - 1) }));
  document.getElementById('next').addEventListener('click', () => goToList({ page: listParams().page + 1 }));
});
