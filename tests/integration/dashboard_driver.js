// dashboard_driver.js BASE_URL OUT_DIR EXAMPLE — drives the dashboard in
// headless Chromium as a person would: open it, submit EXAMPLE, watch the
// job's bar reach 100 %, open the job page, see the picture load, download
// the HDF5 file; then submit the EDMD example with its inputs edited to grow
// slower (about 5 s) and see its bar stand strictly between 0 and 100 %
// while it runs (the live progress), then at 100 %.  Then, on job pages: a
// running job keeps its status word through its progress events and shows
// its stage, φ, time elapsed and left; a job that
// runs out of wall time shows `failed`, its reason, summary and partial-file
// download; a running job cancelled by its button shows `dismissed`.  Times
// are shown in the browser's zone (Asia/Kolkata, GMT+5:30) and say so.  The
// queue line above the list shows what GET /dashboard/queue counts while every
// worker is busy and a job waits, and the list filtered to those jobs drops
// them once cancelled; the waiting job's page shows its inputs (no 404).  A status filter in the URL hash
// lists exactly the API's jobs of that status, also after a reload; the
// checkboxes change it, and a job page leads back to it.  Pages of a small
// limit (a hash parameter) list the API's pages, newer/older and "jobs N–M of
// TOTAL" as the API counts.  At a 390 px viewport the list and a job page are
// no wider than the viewport, also with the job form filled.  The job form,
// made from the pack process's input schema, composes a small RSA job field
// by field (no example): a negative box edge is refused by the API and the
// message is shown at that edge's field; the job posted is exactly the one
// composed; it finishes, and its page shows the summary grouped (asked,
// achieved, audit, model) with units (mm, s).  Every example, filled into the
// form and composed back, keeps its inputs.  An admin (auth off) filters
// the list by owner as GET /jobs?owner= does; a user (auth on) has no such filter.
// Prints PASS/FAIL lines (tests/integration/check.inc) and saves screenshots
// and the downloads (result.h5, partial.h5) in OUT_DIR.
// Env: PLAYWRIGHT_CORE (the installed module), CHROMIUM, SLOW (wait factor),
// TOKEN (auth on: typed into the token field first; the names of the PASS
// lines then end in _auth).
'use strict';
const { chromium } = require(process.env.PLAYWRIGHT_CORE);
const path = require('path');

const [base, out, example] = process.argv.slice(2);
const slow = Number(process.env.SLOW || 1);
const token = process.env.TOKEN || '';
const tag = token ? '_auth' : '';
let failed = 0;
const pass = (n) => console.log('PASS ' + n + tag);
const fail = (n, why) => { failed++; console.log('FAIL ' + n + tag + (why ? ': ' + String(why).split('\n')[0] : '')); };
const shot = (name) => path.join(out, 'dashboard-' + name + tag + '.png');

// RSA in a box too small for φ = 0.8: it places grains until wall_time_s.
const rsaUntilWallTime = (s) => ({
  dim: 2, domain: { box: { size: [40, 40], periodic: false } },
  grading: { type: 'fuller', q: 0.5, d_max: 4 }, d_min: 2,
  phi: { value: 0.8, refers_to: 'resolved' }, delta_d: 0.1,
  rsa: { max_failed_draws: 1e10 }, limits: { wall_time_s: s }, seed: 3,
});

// Submit the example `label` with its inputs changed by edit (the JSON
// textarea, as a person would); the new job's id, once the page shows it in
// place of the link it showed before (whichever job that was).
async function submitEdited(page, label, edit) {
  await page.goto(page.url().replace(/#.*$/, '') + '#/');
  await page.selectOption('#example', { label });
  if (!(await page.isVisible('#inputs'))) await page.click('#json-inputs summary');
  const inputs = edit(JSON.parse(await page.inputValue('#inputs')));
  await page.fill('#inputs', JSON.stringify(inputs));
  const shown = () => { const a = document.querySelector('#submitted a'); return a ? a.textContent.trim() : ''; };
  const before = await page.evaluate(shown);
  await page.click('#submit');
  await page.waitForFunction((b) => {
    const a = document.querySelector('#submitted a');
    return a && a.textContent.trim() !== b;
  }, before);
  return page.evaluate(shown);
}

async function openJob(page, id) {
  await page.goto(page.url().replace(/#.*$/, '') + '#/jobs/' + encodeURIComponent(id));
  await page.waitForFunction((i) => document.getElementById('job-id').textContent === i, id);
}

// The API as the page's user, from the driver (not through the page).
async function apiCall(p, opts) {
  const o = Object.assign({}, opts || {});
  o.headers = Object.assign({ Accept: 'application/json' }, token ? { Authorization: 'Bearer ' + token } : {}, o.headers || {});
  const r = await fetch(base + '/' + p, o);
  if (!r.ok) throw new Error(p + ': ' + r.status + ' ' + (await r.text()).slice(0, 200));
  return r.json();
}
const submitJob = async (process, inputs) => (await apiCall('processes/' + process + '/execution', {
  method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify({ inputs }),
})).jobID;

// Poll fn (the API, from the driver) until it gives a truthy value.
async function until(what, fn, seconds) {
  const end = Date.now() + seconds * 1000 * slow;
  for (;;) {
    const v = await fn();
    if (v) return v;
    if (Date.now() > end) throw new Error('waited ' + seconds * slow + ' s for ' + what);
    await new Promise((r) => setTimeout(r, 200));
  }
}

// The list shows exactly these job ids in this order, and its range line says text.
async function listShows(page, ids, text) {
  await page.waitForFunction(([want, t]) => {
    const got = [...document.querySelectorAll('#jobs tbody tr')].map((tr) => tr.dataset.job);
    return got.join(' ') === want.join(' ') && document.getElementById('range').textContent === t;
  }, [ids, text]);
}

const width = (page) => page.evaluate(() => document.documentElement.scrollWidth);

async function step(name, fn) {
  try { await fn(); pass(name); return true; } catch (e) { fail(name, e.message); return false; }
}

(async () => {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  const page = await browser.newPage({
    viewport: { width: 1200, height: 900 }, acceptDownloads: true,
    timezoneId: 'Asia/Kolkata', locale: 'en-US', // UTC+5:30: a zone no server runs in by accident
  });
  page.setDefaultTimeout(30000 * slow);
  const problems = []; // script errors and CSP violations
  page.on('pageerror', (e) => problems.push(e.message));
  page.on('console', (m) => { if (m.type() === 'error') problems.push(m.text()); });
  page.on('response', (r) => { if (r.status() >= 400) problems.push(r.status() + ' ' + r.url()); });
  let id = '';
  try {
    await step('dashboard_opens', async () => {
      await page.goto(base + '/');
      await page.waitForSelector('#example option', { state: 'attached' });
      if (token) { // the list is refused first, and the page says why
        await page.waitForSelector('#error:has-text("token")');
        problems.length = 0;
        await page.fill('#token', token);
        await page.click('#token-form button');
      }
    });
    await step('dashboard_form_composes_job', async () => {
      const at = (ptr) => `#form-fields [data-pointer="${ptr}"]`;
      await page.selectOption('#process', 'pack');
      await page.selectOption('#example', '');
      await page.waitForSelector(at('/dim') + ' select');
      await page.selectOption(at('/dim') + ' select', '2');
      await page.fill(at('/domain/box/size/0') + ' input', '-1');
      await page.fill(at('/domain/box/size/1') + ' input', '12');
      await page.selectOption(at('/grading') + ' select.alt', 'fuller');
      await page.fill(at('/grading/q') + ' input', '0.5');
      await page.fill(at('/grading/d_max') + ' input', '2');
      await page.fill(at('/d_min') + ' input', '1');
      await page.click(at('/phi') + ' summary');
      await page.fill(at('/phi/value') + ' input', '0.3');
      await page.selectOption(at('/phi/refers_to') + ' select', 'resolved');
      await page.selectOption(at('/algorithm') + ' select', 'rsa');
      await page.fill(at('/seed') + ' input', '7');
      // the API refuses the negative edge; its message stands at that field
      const seen = problems.length;
      await page.click('#submit');
      const msg = await page.waitForSelector(at('/domain/box/size/0') + ' .field-error');
      if (!/> 0/.test(await msg.textContent())) throw new Error('the edge\'s error says ' + await msg.textContent());
      problems.splice(seen); // the 422 was the point
      await page.screenshot({ path: shot('form-error'), fullPage: true });
      await page.fill(at('/domain/box/size/0') + ' input', '12');
      if (await page.isVisible('.field-error')) throw new Error('the error stays after the field is edited');
      await page.screenshot({ path: shot('form'), fullPage: true });
      const before = await page.evaluate(() => { const a = document.querySelector('#submitted a'); return a ? a.textContent : ''; });
      await page.click('#submit');
      await page.waitForFunction((b) => { const a = document.querySelector('#submitted a'); return a && a.textContent !== b; }, before);
      const formId = (await page.textContent('#submitted a')).trim();
      const want = {
        dim: 2, domain: { box: { size: [12, 12] } }, grading: { type: 'fuller', q: 0.5, d_max: 2 }, d_min: 1,
        phi: { value: 0.3, refers_to: 'resolved' }, algorithm: 'rsa', seed: 7,
      };
      const sent = (await apiCall('dashboard/jobs/' + formId + '/inputs')).inputs;
      delete sent.limits; // the service's caps (max_particles, wall_time_s), added to every job
      const canon = (v) => JSON.stringify(v, (k, x) => (x && typeof x === 'object' && !Array.isArray(x) ? Object.fromEntries(Object.entries(x).sort()) : x));
      if (canon(sent) !== canon(want)) throw new Error('the job posted: ' + JSON.stringify(sent));
      const formRow = `tr[data-job="${formId}"]`;
      await page.waitForFunction((sel) => { const tr = document.querySelector(sel); return tr && tr.dataset.status === 'successful'; },
        formRow, { timeout: 60000 * slow });
      await openJob(page, formId);
      await page.waitForSelector('#summary section[data-group="model"]');
      const groups = await page.$$eval('#summary section', (ss) => ss.map((x) => x.dataset.group));
      if (groups.join() !== 'asked,achieved,audit,model') throw new Error('groups: ' + groups);
      const cell = (group, key) => page.textContent(`#summary section[data-group="${group}"] tr[data-key="${key}"] td`);
      const gap = await cell('audit', 'smallest_gap');
      if (!/^\d[\d.e+-]* mm$/.test(gap)) throw new Error('smallest_gap shows ' + gap);
      if (!/ s$/.test(await cell('audit', 'timing.place_s'))) throw new Error('timing.place_s without seconds');
      if (!/^\d+$/.test(await cell('achieved', 'count_placed'))) throw new Error('count_placed shows ' + await cell('achieved', 'count_placed'));
      if ((await cell('asked', 'phi_target_resolved')) !== '0.3') throw new Error('phi_target_resolved not asked 0.3');
      if (!(await cell('model', 'model.dim')).startsWith('2')) throw new Error('the model group lacks dim');
      await page.screenshot({ path: shot('form-job'), fullPage: true });
      await page.goto(base + '/#/');
    });
    await step('dashboard_form_holds_every_example', async () => {
      // each example filled into the form and composed back (as any edit of a
      // field does) gives its inputs unchanged: the form loses nothing
      const canon = (v) => JSON.stringify(v, (k, x) => (x && typeof x === 'object' && !Array.isArray(x) ? Object.fromEntries(Object.entries(x).sort()) : x));
      const all = (await apiCall('dashboard/examples')).examples;
      const lost = [];
      for (const ex of all) {
        await page.selectOption('#example', { label: ex.name.replace(/\.json$/, '') + ' (' + ex.process + ')' });
        await page.waitForFunction((p) => document.getElementById('process').value === p &&
          document.querySelector('#form-fields [data-pointer=""]'), ex.process);
        await page.dispatchEvent('#form-fields', 'change');
        if (canon(JSON.parse(await page.inputValue('#inputs'))) !== canon(ex.inputs)) lost.push(ex.name);
      }
      if (lost.length) throw new Error('the form changes ' + lost.join(', '));
      await page.selectOption('#example', '');
    });
    await step('dashboard_submits_example', async () => {
      const label = example.replace(/\.json$/, '') + ' (pack)';
      await page.selectOption('#example', { label });
      await page.click('#submit');
      const a = await page.waitForSelector('#submitted a');
      id = (await a.textContent()).trim();
      if (!/^[0-9a-f-]{36}$/.test(id)) throw new Error('no job id: ' + id);
    });
    const row = `tr[data-job="${id}"]`;
    await step('dashboard_bar_reaches_100', async () => {
      await page.waitForSelector(row);
      await page.waitForFunction((sel) => {
        const tr = document.querySelector(sel);
        return tr && tr.dataset.status === 'successful' && tr.querySelector('progress').value === 100;
      }, row, { timeout: 60000 * slow });
      await page.screenshot({ path: shot('list'), fullPage: true });
    });
    await step('dashboard_list_time_local_with_zone', async () => {
      const t = await page.textContent(`${row} td.created`);
      if (!t.includes('GMT+5:30')) throw new Error('created shows ' + t);
    });
    await step('dashboard_job_page_picture', async () => {
      await page.click(`${row} a`);
      await page.waitForFunction(() => {
        const img = document.querySelector('img[data-output="picture.png"]');
        return img && img.complete && img.naturalWidth > 0;
      });
      await page.waitForSelector('#summary tr');
      await page.screenshot({ path: shot('job'), fullPage: true });
    });
    await step('dashboard_job_times_local_with_zone', async () => {
      const t = await page.textContent('#job-times');
      if (!/created .*GMT\+5:30/.test(t) || !/finished .*GMT\+5:30/.test(t)) throw new Error('times: ' + t);
    });
    await step('dashboard_downloads_result', async () => {
      const [dl] = await Promise.all([
        page.waitForEvent('download'),
        page.click('a[data-output="result"]'),
      ]);
      await dl.saveAs(path.join(out, 'result' + tag + '.h5'));
      if (dl.suggestedFilename() !== id + '.h5') throw new Error('named ' + dl.suggestedFilename());
    });
    await step('dashboard_bar_moves', async () => {
      await page.goto(base + '/#/');
      await page.selectOption('#example', { label: 'edmd-quartz-2d (pack)' });
      await page.click('#json-inputs summary'); // "Inputs (editable JSON)"
      const inputs = JSON.parse(await page.inputValue('#inputs'));
      inputs.edmd.growth_rate = 0.004; // ~11 progress events 0.5 s apart
      await page.fill('#inputs', JSON.stringify(inputs));
      await page.click('#submit');
      const a = await page.waitForSelector(`#submitted a:not(:has-text("${id}"))`);
      const slowId = (await a.textContent()).trim();
      const sel = `tr[data-job="${slowId}"]`;
      await page.waitForSelector(sel);
      // every value the bar shows, sampled every 20 ms in the page
      await page.evaluate((s) => {
        window.seenValues = [];
        const t = setInterval(() => {
          const tr = document.querySelector(s);
          if (!tr) return;
          window.seenValues.push(tr.querySelector('progress').value);
          if (tr.dataset.status === 'successful' || tr.dataset.status === 'failed') clearInterval(t);
        }, 20);
      }, sel);
      await page.waitForFunction(() => window.seenValues.some((v) => v > 0 && v < 100),
        null, { timeout: 60000 * slow });
      await page.screenshot({ path: shot('running'), fullPage: true });
      await page.waitForFunction((s) => {
        const tr = document.querySelector(s);
        return tr && tr.dataset.status === 'successful' && tr.querySelector('progress').value === 100;
      }, sel, { timeout: 60000 * slow });
      const seen = await page.evaluate(() => [...new Set(window.seenValues)]);
      console.log('BAR ' + seen.join(' '));
    });
    let last = id;
    await step('dashboard_job_page_keeps_status', async () => {
      last = await submitEdited(page, 'meier-quartz-2d (pack)', () => rsaUntilWallTime(300));
      await openJob(page, last);
      await page.waitForSelector('#job-status:text-is("running")', { timeout: 60000 * slow });
      // the status word and the bar, sampled every 20 ms through its progress events
      await page.evaluate(() => {
        window.seenStatus = [];
        window.seenBar = [];
        window.sampler = setInterval(() => {
          window.seenStatus.push(document.getElementById('job-status').textContent);
          window.seenBar.push(document.getElementById('job-progress').value);
        }, 20);
      });
      await page.waitForFunction(() => window.seenStatus.length >= 100 &&
        window.seenBar.some((v) => v > 0 && v < 100), null, { timeout: 60000 * slow });
      const [st, bar] = await page.evaluate(() => { clearInterval(window.sampler); return [window.seenStatus, window.seenBar]; });
      await page.screenshot({ path: shot('job-running'), fullPage: true });
      const msg = await page.textContent('#job-message');
      if (!/^rsa, φ = 0\.\d{4}, \d+ s elapsed, about .* left$/.test(msg)) throw new Error('progress line: ' + msg);
      const other = st.filter((x) => x !== 'running').length;
      if (other) throw new Error(other + ' of ' + st.length + ' samples without the status word: ' + [...new Set(st)].join(' '));
      await page.click('#cancel');
      await page.waitForSelector('#job-status:text-is("dismissed")');
      console.log('BAR ' + [...new Set(bar)].join(' '));
    });
    await step('dashboard_failed_job_page', async () => {
      // the list refresh of the submission lands while the job page, opened
      // meanwhile, waits for the job's status: the page must still follow the job
      const after = (ms) => (r) => setTimeout(() => r.continue().catch(() => {}), ms);
      const list = after(500), status = after(1500);
      await page.route(/\/jobs\?limit=/, list);
      await page.route(/\/jobs\/[0-9a-f-]+$/, status);
      last = await submitEdited(page, 'meier-quartz-2d (pack)', () => rsaUntilWallTime(1));
      await openJob(page, last);
      await page.unroute(/\/jobs\?limit=/, list);
      await page.unroute(/\/jobs\/[0-9a-f-]+$/, status);
      await page.waitForSelector('#job-status:text-is("failed")', { timeout: 60000 * slow });
      await page.waitForSelector('#job-reason:has-text("wall time")');
      await page.waitForSelector('#summary tr');
      const [dl] = await Promise.all([
        page.waitForEvent('download'),
        page.click('a[data-output="result"]:has-text("partial")'),
      ]);
      await dl.saveAs(path.join(out, 'partial' + tag + '.h5'));
      await page.screenshot({ path: shot('failed'), fullPage: true });
    });
    await step('dashboard_cancel_button', async () => {
      last = await submitEdited(page, 'meier-quartz-2d (pack)', () => rsaUntilWallTime(300));
      await openJob(page, last);
      await page.click('#cancel');
      await page.waitForSelector('#job-status:text-is("dismissed")');
      if (await page.isVisible('#cancel')) throw new Error('the button stays after the job is dismissed');
      await page.screenshot({ path: shot('dismissed'), fullPage: true });
    });
    await step('dashboard_queue_line', async () => {
      // every worker busy with a job that runs until cancelled, and one job waiting
      const max = (await apiCall('dashboard/queue')).workers_max;
      const held = [];
      try {
        for (let i = 0; i <= max; i++) held.push(await submitJob('pack', rsaUntilWallTime(300)));
        const q = await until('all workers busy and a job waiting', async () => {
          const d = await apiCall('dashboard/queue');
          return d.running === max && d.workers_busy === max && d.accepted === 1 ? d : null;
        }, 60);
        const running = (await apiCall('jobs?status=running&limit=1')).numberMatched;
        if (running !== q.running) throw new Error(`the job list counts ${running} running, the queue ${q.running}`);
        // the list filtered to them: the rows are the held jobs, the line the API's counts
        await page.goto(base + '/#/?status=running,accepted&process=pack');
        await page.waitForFunction((want) => Object.keys(want).every((k) => {
          const e = document.getElementById('q-' + k);
          return e && e.textContent === String(want[k]);
        }), q);
        const listed = (await apiCall('jobs?status=running,accepted&processID=pack&limit=50')).jobs.map((j) => j.jobID);
        if (listed.slice().sort().join(' ') !== held.slice().sort().join(' ')) throw new Error('the API lists other jobs: ' + listed);
        await listShows(page, listed, `jobs 1–${held.length} of ${held.length}`);
        await page.screenshot({ path: shot('queue'), fullPage: true });
        // the waiting job's page shows its inputs (no worker has its job file yet)
        const waitingId = (await apiCall('jobs?status=accepted&limit=1')).jobs[0].jobID;
        await openJob(page, waitingId);
        await page.waitForSelector('#job-status:text-is("accepted")');
        await page.waitForSelector('#job-inputs:has-text("wall_time_s")');
        await page.goto(base + '/#/?status=running,accepted&process=pack');
        for (const j of held) await apiCall('jobs/' + j, { method: 'DELETE' }).catch(() => {});
        held.length = 0;
        // the refresh under the filter drops them, and the line counts no job
        await listShows(page, [], 'no jobs match the filters');
        await page.waitForFunction(() => ['q-accepted', 'q-running', 'q-workers_busy'].every((k) => document.getElementById(k).textContent === '0'),
          null, { timeout: 60000 * slow });
      } finally {
        for (const j of held) await apiCall('jobs/' + j, { method: 'DELETE' }).catch(() => {});
      }
    });
    await step('dashboard_filter_status', async () => {
      const all = (await apiCall('jobs?limit=1000')).jobs;
      const of = (st) => all.filter((j) => j.status === st).map((j) => j.jobID);
      if (!of('successful').length || !of('failed').length) throw new Error('needs successful and failed jobs');
      const shows = async (st) => {
        await listShows(page, of(st), `jobs 1–${of(st).length} of ${of(st).length}`);
        const boxes = await page.$$eval('#filters input[name="status"]', (bs) => bs.filter((b) => b.checked).map((b) => b.value));
        if (boxes.join() !== st) throw new Error(`the boxes checked: ${boxes} (the filter is ${st})`);
      };
      await page.goto(base + '/#/?status=successful');
      await shows('successful');
      await page.reload();
      await shows('successful');
      if (!page.url().endsWith('#/?status=successful')) throw new Error('the reload lost the filter: ' + page.url());
      await page.check('#filters input[value="failed"]');
      await page.uncheck('#filters input[value="successful"]');
      await page.waitForFunction(() => location.hash === '#/?status=failed');
      await shows('failed');
      await page.screenshot({ path: shot('filtered'), fullPage: true });
      // a job page leads back to the filtered list
      await page.click(`tr[data-job="${of('failed')[0]}"] a`);
      await page.waitForFunction((i) => document.getElementById('job-id').textContent === i, of('failed')[0]);
      await page.click('#back');
      await shows('failed');
    });
    await step('dashboard_owner_filter', async () => {
      const me = await apiCall('dashboard/me');
      await page.goto(base + '/#/');
      await page.waitForSelector(row);
      await page.waitForFunction((admin) => document.getElementById('f-owner-pick').hidden === !admin, me.admin);
      if (!me.admin) return; // a user's list is its own: no owner filter to offer
      const mine = await apiCall('jobs?limit=50&owner=' + encodeURIComponent(me.owner));
      if (!mine.jobs.length) throw new Error('the API lists no job of ' + me.owner);
      await page.fill('#f-owner', me.owner);
      await page.press('#f-owner', 'Enter');
      await page.waitForFunction((o) => location.hash === '#/?owner=' + encodeURIComponent(o), me.owner);
      await listShows(page, mine.jobs.map((j) => j.jobID), `jobs 1–${mine.jobs.length} of ${mine.numberMatched}`);
      await page.goto(base + '/#/?owner=nobody-here');
      await listShows(page, [], 'no jobs match the filters');
    });
    await step('dashboard_pages', async () => {
      const limit = 3;
      let total = (await apiCall('jobs?limit=1')).numberMatched;
      if (total <= 2 * limit) { // three pages, the last one short
        const ex = (await apiCall('dashboard/examples')).examples.find((e) => e.name === example);
        while (total <= 2 * limit) { await submitJob(ex.process, ex.inputs); total++; }
      }
      // every job ended: the lists by status below hold still
      await until('every job ended', async () => (await apiCall('jobs?status=accepted,running&limit=1')).numberMatched === 0, 60);
      const pageOf = async (n, q) => (await apiCall(`jobs?limit=${limit}&offset=${(n - 1) * limit}${q || ''}`)).jobs.map((j) => j.jobID);
      const range = (n, len) => `jobs ${(n - 1) * limit + 1}–${(n - 1) * limit + len} of ${total}`;
      const buttons = async (prev, next) => {
        const got = [await page.isEnabled('#prev'), await page.isEnabled('#next')];
        if (got[0] !== prev || got[1] !== next) throw new Error(`newer/older enabled: ${got} (want ${prev},${next})`);
      };
      await page.goto(base + `/#/?limit=${limit}`);
      const p1 = await pageOf(1), p2 = await pageOf(2);
      await listShows(page, p1, range(1, limit));
      await buttons(false, true);
      await page.click('#next');
      await listShows(page, p2, range(2, limit));
      if (!/page=2/.test(page.url())) throw new Error('the page is not in the hash: ' + page.url());
      await page.reload();
      await listShows(page, p2, range(2, limit));
      await buttons(true, true);
      const last = Math.ceil(total / limit), pl = await pageOf(last);
      await page.goto(base + `/#/?page=${last}&limit=${limit}`);
      await listShows(page, pl, range(last, pl.length));
      await buttons(true, false);
      await page.screenshot({ path: shot('pages'), fullPage: true });
      await page.click('#prev');
      await listShows(page, await pageOf(last - 1), range(last - 1, limit));
      // filters and pages together: the second page of the ended jobs
      const q = '&status=successful,failed,dismissed';
      const ended = (await apiCall(`jobs?limit=1${q}`)).numberMatched;
      const e2 = await pageOf(2, q);
      await page.goto(base + `/#/?status=successful,failed,dismissed&page=2&limit=${limit}`);
      await listShows(page, e2, `jobs ${limit + 1}–${limit + e2.length} of ${ended}`);
    });
    await step('dashboard_fits_390px', async () => {
      await page.setViewportSize({ width: 390, height: 844 });
      await page.goto(base + '/#/');
      await page.waitForSelector(row);
      const list = await width(page);
      await page.screenshot({ path: shot('list-390'), fullPage: true });
      await openJob(page, id);
      await page.waitForSelector('#summary tr');
      await page.waitForFunction(() => [...document.images].every((i) => i.complete));
      const job = await width(page);
      await page.screenshot({ path: shot('job-390'), fullPage: true });
      // the form filled by an example, its optional groups opened
      await page.goto(base + '/#/');
      await page.selectOption('#example', { label: 'edmd-quartz-2d (pack)' });
      await page.waitForSelector('#form-fields [data-pointer="/edmd"]:not([hidden])');
      await page.$$eval('#form-fields details', (ds) => ds.forEach((d) => { d.open = true; }));
      const form = await width(page);
      await page.screenshot({ path: shot('form-390'), fullPage: true });
      if (list > 390 || job > 390 || form > 390) throw new Error(`scrollWidth at 390 px: list ${list}, job page ${job}, form ${form}`);
    });
    if (problems.length) fail('dashboard_no_script_errors', problems.join(' | '));
    else pass('dashboard_no_script_errors');
  } catch (e) {
    fail('dashboard_driver', e.message);
  } finally {
    await page.screenshot({ path: shot('last'), fullPage: true }).catch(() => {});
    await browser.close();
  }
  console.log('JOB ' + id);
  process.exit(failed ? 1 : 0);
})().catch((e) => { fail('dashboard_driver', e.message); process.exit(1); });
