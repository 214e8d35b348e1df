// The try-on page in a real browser: Debian's headless chromium driven by puppeteer-core (from
// web/node_modules; no browser download) against `drape serve` on a free loopback port. It makes a
// body from measurements, tries the shirt on, checks that the canvas shows skin and cloth of the
// shirt's colour, toggles the fit map, follows the share link's address, and uploads a malformed
// file. Screenshots go to OUT_DIR (kept as test artefacts). The shirt is dressed a little coarser
// than drape's default (--edge 0.035) to keep the test short.
//
//   node browser_test.mjs DRAPE_BINARY WEB_DIR CORPUS_DIR OUT_DIR
// Exit status 77 (ctest SKIP) when chromium or web/node_modules is missing, or under sanitizers.
import { spawn } from 'node:child_process';
import { existsSync, mkdirSync, rmSync } from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { pathToFileURL } from 'node:url';

const [drape, webDir, corpusDir, outDir] = process.argv.slice(2).map((p) => path.resolve(p));
const chromium = process.env.CHROMIUM || '/usr/bin/chromium';
const skip = (why) => { console.log(`SKIPPED: ${why}`); process.exit(77); };
if (process.env.DRAPE_SANITIZED === '1') skip('the browser test does not run under the sanitizers');
if (!existsSync(chromium)) skip(`no chromium at ${chromium} (make deps installs it)`);
if (!existsSync(path.join(webDir, 'node_modules', 'puppeteer-core')) || !existsSync(path.join(webDir, 'node_modules', 'three')))
  skip(`${webDir}/node_modules is missing (make deps runs npm there)`);

const require = createRequire(path.join(webDir, 'package.json'));
const puppeteer = (await import(pathToFileURL(require.resolve('puppeteer-core')).href)).default;

rmSync(outDir, { recursive: true, force: true });
mkdirSync(outDir, { recursive: true });
let failures = 0;
const started = Date.now();
const check = (ok, what) => {
  console.log(`${ok ? 'ok  ' : 'FAIL'} ${((Date.now() - started) / 1000).toFixed(1).padStart(5)} s  ${what}`);
  if (!ok) failures += 1;
};

// The server: its first line on stdout says the port.
const server = spawn(drape, ['serve', '--port', '0', '--data', path.join(outDir, 'data'), '--web', webDir,
                             '--workers', '1', '--keep', '1h', '--edge', '0.035', '--no-warm-up'], { stdio: ['ignore', 'pipe', 'inherit'] });
const port = await new Promise((resolve, reject) => {
  let text = '';
  server.stdout.on('data', (d) => {
    text += d;
    const m = text.match(/listening on http:\/\/[^:]+:(\d+)/);
    if (m) resolve(Number(m[1]));
  });
  server.on('exit', (code) => reject(new Error(`drape serve exited with ${code}`)));
  setTimeout(() => reject(new Error('drape serve did not say its port')), 30000);
});
const base = `http://127.0.0.1:${port}/`;

const browser = await puppeteer.launch({
  executablePath: chromium,
  headless: true,
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--window-size=1440,1000'],
});
const page = await browser.newPage();
await page.setViewport({ width: 1440, height: 1000 });
const pageErrors = [];
page.on('pageerror', (e) => pageErrors.push(String(e)));
// The browser logs every refused request as a console error: the malformed upload's 400 is expected.
page.on('console', (m) => {
  if (m.type() === 'error' && !/status of 400/.test(m.text())) pageErrors.push(m.text());
});
const shot = (name) => page.screenshot({ path: path.join(outDir, name) });
// A view is checked once the page has drawn it (data-drawn follows each frame rendered).
const waitView = (view, timeout = 120000) =>
  page.waitForSelector(`body[data-view="${view}"][data-drawn="${view}"]`, { timeout });

// Pixels of the 3D view near the hue of drape's skin tone and near the hue of the garment's colour
// (shading changes their lightness, not their hue), as fractions of the view.
async function pixels(colour) {
  return page.evaluate((hex) => {
    const c = document.getElementById('canvas');
    const t = document.createElement('canvas');
    t.width = c.width;
    t.height = c.height;
    const ctx = t.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, t.width, t.height).data;
    const g = [1, 3, 5].map((i) => parseInt(hex.substr(i, 2), 16));
    const hue = (r, gg, b) => Math.atan2(Math.sqrt(3) * (gg - b), 2 * r - gg - b);
    const garmentHue = hue(...g);
    const skinHue = hue(226, 186, 160);  // drape's skin tone
    const near = (h, to, within) => Math.abs(Math.atan2(Math.sin(h - to), Math.cos(h - to))) < within;
    let skin = 0, cloth = 0;
    for (let i = 0; i < d.length; i += 4) {
      const [r, gg, b] = [d[i], d[i + 1], d[i + 2]];
      const chroma = Math.max(r, gg, b) - Math.min(r, gg, b);
      if (chroma < 25) continue;  // the grey backdrop and floor
      const h = hue(r, gg, b);
      if (near(h, garmentHue, 0.35)) cloth += 1;
      else if (near(h, skinHue, 0.25)) skin += 1;
    }
    const n = d.length / 4;
    return { skin: skin / n, cloth: cloth / n };
  }, colour);
}

try {
  await page.goto(base, { waitUntil: 'networkidle0' });
  await page.waitForSelector('body[data-ready="true"]', { timeout: 30000 });
  const garments = await (await fetch(`${base}api/garments`)).json();
  const shirt = garments.garments.find((g) => g.name === 'shirt');
  check(!!shirt, 'the catalogue has the shirt');
  const thumbs = await page.$$eval('.card img', (imgs) => imgs.map((i) => i.complete && i.naturalWidth > 0));
  check(thumbs.length === garments.garments.length && thumbs.every(Boolean), `${thumbs.length} thumbnails shown`);

  // A body from measurements.
  for (const [name, value] of [['height', '168'], ['bust', '90'], ['waist', '72'], ['hips', '97']]) {
    await page.$eval(`#measure-form input[name=${name}]`, (e) => { e.value = ''; });
    await page.type(`#measure-form input[name=${name}]`, value);
  }
  await page.click('#make-body');
  await waitView('body', 60000);
  const bodyPixels = await pixels(shirt.colour);
  check(bodyPixels.skin > 0.01, `the body is shown (${(100 * bodyPixels.skin).toFixed(1)} % skin)`);
  await shot('body.png');

  // The shirt in M, with progress while it is dressed.
  await page.click('.card[data-garment="shirt"]');
  await page.click('#sizes button[data-size="M"]');
  await page.click('#tryon');
  await page.waitForSelector('#progress:not([hidden])', { timeout: 60000 });
  check(true, 'progress is shown while dressing');
  await waitView('dressed');
  const dressed = await pixels(shirt.colour);
  check(dressed.cloth > 0.01, `the shirt is shown in its colour (${(100 * dressed.cloth).toFixed(1)} % of the view)`);
  check(dressed.skin > 0.002, `the body shows beside it (${(100 * dressed.skin).toFixed(1)} % skin)`);
  const verdict = await page.$eval('#verdict', (e) => (e.hidden ? '' : e.innerText));
  check(/Size M/.test(verdict) && /(good|loose|tight)/.test(verdict), `the fit is told in words: ${verdict.split('\n')[0]}`);
  await shot('dressed.png');

  // The fit map: cloth and skin in drape's strain and pressure colours, with a legend.
  await page.click('#fitmap');
  await waitView('fitmap', 30000);
  const fit = await pixels(shirt.colour);
  const legend = await page.$eval('#legend', (e) => (e.hidden ? '' : e.innerText));
  check(await page.$eval('#fitmap', (e) => e.getAttribute('aria-pressed')) === 'true', 'the fit-map button is pressed');
  check(/strain/.test(legend) && /pressure/.test(legend), 'the legend names strain and pressure');
  check(fit.skin < dressed.skin / 3, `the skin takes the pressure colours (${(100 * fit.skin).toFixed(2)} % skin-coloured left)`);
  await shot('fitmap.png');
  await page.click('#fitmap');
  await waitView('dressed', 30000);
  check(true, 'the fit map toggles back');

  // Keyboard: every control is reached with Tab.
  await page.focus('body');
  const reached = new Set();
  for (let i = 0; i < 60; i += 1) {
    await page.keyboard.press('Tab');
    reached.add(await page.evaluate(() => document.activeElement.id || document.activeElement.dataset.garment ||
                                          document.activeElement.dataset.size || document.activeElement.name || ''));
  }
  for (const id of ['make-body', 'shirt', 'M', 'tryon', 'fitmap', 'share', 'viewer'])
    check(reached.has(id), `"${id}" is reachable with the keyboard`);

  // A malformed upload: its error in plain words, and the page keeps working.
  await page.click('#tab-upload');
  const input = await page.$('#upload-form input[type=file]');
  await input.uploadFile(path.join(corpusDir, 'nan_vertex.obj'));
  await page.click('#upload-body');
  await page.waitForSelector('#error:not([hidden])', { timeout: 30000 });
  const error = await page.$eval('#error', (e) => e.innerText);
  check(/could not read your scan/i.test(error) && !/\//.test(error), `the upload's error: ${error}`);
  await shot('upload_error.png');
  // The share link reproduces the try-on from the measurements, garment and size in its address.
  await page.click('#share');
  const shared = await page.evaluate(() => location.href);
  check(/garment=shirt/.test(shared) && /size=M/.test(shared) && /height=1.68/.test(shared), `share link ${shared}`);
  await page.close();  // one page at a time: the machine's cores go to the dressing
  const other = await browser.newPage();
  await other.setViewport({ width: 1440, height: 1000 });
  // The shared page asks for the same body and try-on by itself; seeing it ask (and start dressing)
  // is enough: the dressing itself was checked above.
  const asked = { body: null, tryon: null };
  other.on('request', (r) => {
    if (r.method() !== 'POST') return;
    if (r.url().endsWith('/api/bodies')) asked.body = JSON.parse(r.postData() || 'null');
    if (r.url().endsWith('/api/tryons')) asked.tryon = JSON.parse(r.postData() || 'null');
  });
  await other.goto(shared, { waitUntil: 'load' });
  await other.waitForSelector('#progress:not([hidden])', { timeout: 60000 });
  check(asked.body && asked.body.sex === 'female' && asked.body.measurements.height === 1.68 &&
        asked.body.measurements.hips === 0.97, `the shared link makes the same body: ${JSON.stringify(asked.body)}`);
  check(asked.tryon && asked.tryon.garment === 'shirt' && asked.tryon.size === 'M',
        `and tries the same garment and size on: ${JSON.stringify(asked.tryon)}`);
  await other.close();

  check(pageErrors.length === 0, `no script errors on the page${pageErrors.length ? `: ${pageErrors.join('; ')}` : ''}`);
} catch (e) {
  check(false, String(e && e.stack ? e.stack : e));
  if (!page.isClosed()) await shot('failure.png').catch(() => {});
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
console.log(failures ? `${failures} checks failed; screenshots in ${outDir}` : `all checks passed; screenshots in ${outDir}`);
process.exit(failures ? 1 : 0);
