// A picture of a report as a browser shows it (the README's): headless chromium, 1200 px wide,
// the page from its top down to the end of the 3-D view.
//
// node tests/report/screenshot.mjs REPORT_MODULE_DIR PAGE.html OUT.png
import { createRequire } from 'node:module';
import path from 'node:path';

const [moduleDir, page, out] = process.argv.slice(2);
const require = createRequire(path.join(path.resolve(moduleDir), 'package.json'));
const { chromium } = require('playwright-core');

const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM || '/usr/bin/chromium',
  args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader'],
});
try {
  const context = await browser.newContext({ offline: true, viewport: { width: 1200, height: 900 } });
  const p = await context.newPage();
  await p.goto('file://' + path.resolve(page));
  await p.waitForFunction(() => document.body.dataset.viewer === 'rendered', null, { timeout: 30000 });
  const view = await p.locator('#needles').boundingBox();
  await p.screenshot({
    path: out, fullPage: true, clip: { x: 0, y: 0, width: 1200, height: view.y + view.height },
  });
} finally {
  await browser.close();
}
