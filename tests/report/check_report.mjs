// The HTML report in a real browser (Debian's chromium, headless, WebGL through SwiftShader):
// every report the CLI writes (simulate, screen and optimize --report, and `mneedle report`) opens
// offline without a console error, its plots are SVG with content, and its 3-D view draws a
// needle (a screenshot of the canvas that is not blank) and redraws when another is picked.
//
// node tests/report/check_report.mjs MNEEDLE REPORT_MODULE_DIR WORK_DIR SOURCE_DIR [SCREENSHOT.png]
import { execFileSync } from 'node:child_process';
import { mkdirSync, rmSync, existsSync } from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';

const [mneedle, moduleDir, work, source, screenshot] = process.argv.slice(2);
const require = createRequire(path.join(moduleDir, 'package.json'));
const { chromium } = require('playwright-core');
const { PNG } = require('pngjs');

const failures = [];
const fail = (what) => { failures.push(what); console.error('FAIL ' + what); };

function mneedleRun(args) {
  execFileSync(mneedle, args, { cwd: source, stdio: ['ignore', 'pipe', 'inherit'] });
}

rmSync(work, { recursive: true, force: true });
mkdirSync(work, { recursive: true });
const scene = 'designs/scenes/silicone_phantom.toml';
// Small runs: the analytic pre-puncture model where it is enough, a handful of evaluations.
mneedleRun(['simulate', 'tests/assets/scenes/axisymmetric_punch.toml', '--quiet', '--report',
  path.join(work, 'simulate')]);
mneedleRun(['screen', 'designs', '--scene', scene, '--model', 'analytic', '--json', '--report',
  path.join(work, 'screen')]);
mneedleRun(['optimize', '--plugin', 'cone', '--scene', 'designs/scenes/optimize_silicone.toml',
  '--vary', 'half_angle', '--model', 'analytic', '--max-evals', '5', '--json', '--report',
  path.join(work, 'optimize')]);
// The standalone command on a result written by --json.
mneedleRun(['report', path.join(work, 'screen', 'result.json'), '-o',
  path.join(work, 'screen_again.html')]);

const pages = [
  { file: path.join(work, 'simulate', 'report.html'), needles: 1, plots: 1 },
  { file: path.join(work, 'screen', 'report.html'), needles: 4, plots: 1 },
  { file: path.join(work, 'optimize', 'report.html'), needles: 1, plots: 2 },
  { file: path.join(work, 'screen_again.html'), needles: 4, plots: 1 },
];

// Share of pixels that differ from the view's background (0xf7f7f7) by more than a little.
function drawnShare(png) {
  const image = PNG.sync.read(png);
  let drawn = 0;
  for (let i = 0; i < image.data.length; i += 4) {
    const d = Math.abs(image.data[i] - 0xf7) + Math.abs(image.data[i + 1] - 0xf7) +
      Math.abs(image.data[i + 2] - 0xf7);
    if (d > 24) drawn++;
  }
  return drawn / (image.width * image.height);
}

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  for (const p of pages) {
    const name = path.relative(work, p.file);
    if (!existsSync(p.file)) { fail(name + ': not written'); continue; }
    // Offline: the page must fetch nothing (third-party code is in it).
    const context = await browser.newContext({ offline: true, viewport: { width: 1200, height: 900 } });
    const page = await context.newPage();
    const errors = [];
    page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
    page.on('pageerror', (e) => errors.push(e.message));
    page.on('request', (r) => {
      if (!r.url().startsWith('file:') && !r.url().startsWith('data:')) errors.push('fetched ' + r.url());
    });
    await page.goto('file://' + p.file);
    try {
      await page.waitForFunction(() => document.body.dataset.viewer === 'rendered', null,
        { timeout: 30000 });
    } catch (e) {
      fail(name + ': the 3-D view never said it rendered');
    }
    const svgs = await page.$$eval('figure.plot svg', (list) => list.map((s) => s.querySelectorAll('*').length));
    if (svgs.length !== p.plots) fail(`${name}: ${svgs.length} plots, expected ${p.plots}`);
    for (const n of svgs) if (n < 50) fail(`${name}: a plot with only ${n} elements`);
    const options = await page.$$eval('#needle-select option', (l) => l.length);
    if (options !== p.needles) fail(`${name}: ${options} needles in the 3-D view, expected ${p.needles}`);
    const canvas = page.locator('#needle-view canvas');
    if ((await canvas.count()) !== 1) {
      fail(name + ': no canvas');
    } else {
      const first = await canvas.screenshot();
      const share = drawnShare(first);
      // A needle fills a few per cent of the view at least (the grid alone is thin lines).
      if (!(share > 0.02)) fail(`${name}: the 3-D view is blank (${(100 * share).toFixed(2)} % drawn)`);
      if (p.needles > 1) {
        await page.selectOption('#needle-select', String(p.needles - 1));
        const second = await canvas.screenshot();
        if (Buffer.compare(first, second) === 0) fail(name + ': picking another needle changed nothing');
        // A ranking row picks its needle too.
        await page.click('tr[data-needle="0"]');
        const third = await canvas.screenshot();
        if (Buffer.compare(third, second) === 0) fail(name + ': clicking a row changed nothing');
      }
      // Turning it with the mouse redraws it.
      const box = await canvas.boundingBox();
      const before = await canvas.screenshot();
      await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
      await page.mouse.down();
      await page.mouse.move(box.x + box.width / 2 + 120, box.y + box.height / 2 + 30, { steps: 5 });
      await page.mouse.up();
      if (Buffer.compare(before, await canvas.screenshot()) === 0) fail(name + ': dragging did not turn the needle');
    }
    for (const e of errors) fail(`${name}: console error: ${e}`);
    if (screenshot && p.file.endsWith(path.join('screen', 'report.html'))) {
      await page.selectOption('#needle-select', '0');
      await page.screenshot({ path: screenshot, fullPage: true });
    }
    console.log(`${name}: ${svgs.length} plots, ${options} needles, ${errors.length} console errors`);
    await context.close();
  }
} finally {
  await browser.close();
}
if (failures.length) {
  console.error(`${failures.length} check(s) failed`);
  process.exit(1);
}
console.log('every report rendered');
