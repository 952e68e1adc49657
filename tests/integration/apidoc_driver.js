// apidoc_driver.js BASE_URL OUT_DIR OPERATIONS — opens the service's HTML
// pages in headless Chromium: the interactive API page (/api?f=html, the
// landing page's service-doc) must show at least OPERATIONS operations of
// the OpenAPI document, and it and the HTML views of /processes and /jobs
// must load without a script error, a Content-Security-Policy violation or a
// failed request, and without a request to another origin.  Prints PASS/FAIL
// lines (tests/integration/check.inc); screenshots in OUT_DIR.
// Env: PLAYWRIGHT_CORE (the installed module), CHROMIUM, SLOW (wait factor).
'use strict';
const { chromium } = require(process.env.PLAYWRIGHT_CORE);
const path = require('path');

const [base, out, operations] = process.argv.slice(2);
const slow = Number(process.env.SLOW || 1);
const pass = (n) => console.log('PASS ' + n);
const fail = (n, why) => console.log('FAIL ' + n + (why ? ': ' + String(why).split('\n')[0] : ''));

(async () => {
  const browser = await chromium.launch({
    executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
  });
  try {
    const visit = async (name, url, ready) => {
      const page = await browser.newPage({ viewport: { width: 1200, height: 900 } });
      page.setDefaultTimeout(30000 * slow);
      const problems = [];
      page.on('pageerror', (e) => problems.push(e.message));
      page.on('console', (m) => { if (m.type() === 'error') problems.push(m.text()); });
      page.on('response', (r) => { if (r.status() >= 400) problems.push(r.status() + ' ' + r.url()); });
      page.on('request', (r) => {
        if (!r.url().startsWith(base) && !r.url().startsWith('data:')) problems.push('elsewhere: ' + r.url());
      });
      try {
        await page.goto(base + url);
        await ready(page);
        await page.screenshot({ path: path.join(out, 'html-' + name + '.png'), fullPage: false });
        if (problems.length) fail(name + '_clean', problems.join(' | '));
        else pass(name + '_clean');
      } catch (e) {
        fail(name + '_loads', e.message);
      } finally {
        await page.close();
      }
    };
    await visit('api_page', '/api?f=html', async (page) => {
      await page.waitForSelector('.opblock');
      const n = await page.locator('.opblock').count();
      if (n >= Number(operations)) pass('api_page_operations');
      else fail('api_page_operations', n + ' shown, ' + operations + ' documented');
    });
    for (const list of ['processes', 'jobs']) {
      await visit(list + '_page', '/' + list + '?f=html', async (page) => {
        await page.waitForSelector('table');
        // the stylesheet applied: the header band is the dashboard's colour
        const bg = await page.$eval('header', (e) => getComputedStyle(e).backgroundColor);
        if (bg === 'rgb(45, 62, 80)') pass(list + '_page_styled');
        else fail(list + '_page_styled', bg);
      });
    }
  } finally {
    await browser.close();
  }
})().catch((e) => { fail('apidoc_driver', e.message); process.exit(1); });
