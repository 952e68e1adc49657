// dashboard_driver.js BASE_URL OUT_DIR EXAMPLE — drives the dashboard in
// headless Chromium as a person would: open it, submit EXAMPLE, watch the
// job's bar reach 100 %, open the job page, see the picture load, download
// the HDF5 file; then submit the EDMD example with its inputs edited to grow
// slower (about 5 s) and see its bar stand strictly between 0 and 100 %
// while it runs (the live progress), then at 100 %.  Prints PASS/FAIL lines (tests/integration/check.inc) and
// saves screenshots and the download in OUT_DIR.
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

async function step(name, fn) {
  try { await fn(); pass(name); return true; } catch (e) { fail(name, e.message); return false; }
}

(async () => {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  const page = await browser.newPage({ viewport: { width: 1200, height: 900 }, acceptDownloads: true });
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
    await step('dashboard_job_page_picture', async () => {
      await page.click(`${row} a`);
      await page.waitForFunction(() => {
        const img = document.querySelector('img[data-output="picture.png"]');
        return img && img.complete && img.naturalWidth > 0;
      });
      await page.waitForSelector('#summary tr');
      await page.screenshot({ path: shot('job'), fullPage: true });
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
      await page.click('#submit-form details summary'); // "Inputs (editable JSON)"
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
