// Opens a page in headless Chromium (Debian's /usr/bin/chromium, driven by playwright-core from
// export/viewer's pinned packages) and prints, as JSON, what a test needs to judge it:
//   state      window.lacunaPage once the page says it is ready (or the wait timed out)
//   console    every console message: {type, text}
//   errors     uncaught exceptions on the page
//   requests   every URL the page asked for other than itself
//   screenshot the PNG written (of the element given by --element, else the whole page)
//
//   node tests/browser/page_check.mjs PAGE.html --screenshot OUT.png [--element '#viewer'] [--click SELECTOR]...
//        [--timeout-ms 60000]
//
// --click (repeatable) clicks the page's controls in order once it is ready, before the screenshot.
//
// Exit 0 when it could report (whatever the page did), 2 for bad arguments, 3 when Chromium failed.
import { createRequire } from 'node:module';
import { dirname, resolve } from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const require = createRequire(resolve(here, '../../export/viewer/package.json'));
const { chromium } = require('playwright-core');

const args = process.argv.slice(2);
const option = (name, fallback) => {
  const i = args.indexOf(name);
  return i >= 0 && i + 1 < args.length ? args[i + 1] : fallback;
};
const pagePath = args[0];
const screenshot = option('--screenshot', '');
if (!pagePath || pagePath.startsWith('--') || !screenshot) {
  console.error('usage: node page_check.mjs PAGE.html --screenshot OUT.png [--element SELECTOR] [--timeout-ms MS]');
  process.exit(2);
}
const element = option('--element', '');
const clicks = args.flatMap((a, i) => (a === '--click' && i + 1 < args.length ? [args[i + 1]] : []));
const timeoutMs = Number(option('--timeout-ms', '60000'));
const url = pathToFileURL(resolve(pagePath)).href;

let browser;
try {
  browser = await chromium.launch({
    executablePath: process.env.LACUNA_CHROMIUM || '/usr/bin/chromium',
    // No sandbox as root; WebGL on the CPU (SwiftShader); no background connections on a closed network.
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--disable-quic',
           '--no-first-run', '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  const page = await browser.newPage({ viewport: { width: 1280, height: 1000 } });
  const result = { url, state: null, console: [], errors: [], requests: [], screenshot, timed_out: false };
  page.on('console', (m) => result.console.push({ type: m.type(), text: m.text() }));
  page.on('pageerror', (e) => result.errors.push(String(e && e.stack ? e.stack : e)));
  page.on('request', (r) => { if (r.url() !== url) result.requests.push(r.url()); });
  await page.goto(url, { waitUntil: 'load', timeout: timeoutMs });
  try {
    await page.waitForFunction(() => window.lacunaPage && (window.lacunaPage.ready || window.lacunaPage.errors.length),
                               null, { timeout: timeoutMs });
  } catch {
    result.timed_out = true;
  }
  for (const selector of clicks) await page.click(selector, { timeout: timeoutMs });
  result.state = await page.evaluate(() => window.lacunaPage || null);
  const target = element ? page.locator(element) : page;
  await target.screenshot({ path: screenshot, ...(element ? {} : { fullPage: false }) });
  console.log(JSON.stringify(result));
} catch (e) {
  console.error(`page_check: ${e && e.stack ? e.stack : e}`);
  process.exitCode = 3;
} finally {
  if (browser) await browser.close();
}
