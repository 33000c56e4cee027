// The viewer example in headless Chromium (run by .ci/wasm when chromium
// is installed; CI installs it):
//   SPLITSTREAM_BROWSER_DEPS=DIR node sdk-wasm/tests/browser/viewer.mjs WEB_PKG_DIR
// WEB_PKG_DIR holds `wasm-bindgen --target web` output; DIR has
// node_modules/playwright-core. The page streams conformance vectors over
// HTTP range requests (serve.mjs), draws with WebGL2 (SwiftShader here)
// and must end on the manifest's state hash with the mesh on screen; a
// corrupt stream must show the decoder's error class.
import assert from 'node:assert/strict';
import { createRequire } from 'node:module';
import { join, resolve } from 'node:path';

import { serve } from '../../examples/viewer/serve.mjs';
import { newestVectors, root } from '../vectors.mjs';

const pkgDir = resolve(process.argv[2] ?? '');
const deps = resolve(process.env.SPLITSTREAM_BROWSER_DEPS ?? '');
const { chromium } = createRequire(join(deps, 'package.json'))('playwright-core');

const { dir, manifest } = newestVectors();
const vector = (name) => manifest.vectors.find((v) => v.name === name);

const { server, url, log } = await serve({
  '/': join(root, 'sdk-wasm/examples/viewer'),
  '/pkg/': pkgDir,
  '/v/': dir,
});
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  args: ['--no-sandbox', '--disable-background-networking', '--disable-component-update',
    '--disable-sync', '--no-first-run', '--disable-quic'],
});
try {
  const page = await browser.newPage({ viewport: { width: 640, height: 480 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));

  // A scanned mesh and a 31-bit terrain (far from the origin: the viewer
  // draws around the centre) refined to their last level.
  for (const name of ['bunny-npm', 'bits-31-terrain-constrained-height']) {
    const v = vector(name);
    log.length = 0;
    await page.goto(`${url}/?stream=/v/${v.file}&level=99`);
    await page.waitForFunction(
      (levels) => window.viewer.state === 'error' || (window.viewer.state === 'idle' && window.viewer.levelsDone === levels),
      v.result.levels,
      { timeout: 60_000 },
    );
    const report = await page.evaluate(() => ({ ...window.viewer, covered: window.viewer.coverage() }));
    assert.equal(report.error, undefined, `${name}: ${report.error}`);
    assert.equal(report.hash, v.result.state_hash, name);
    assert.equal(report.vertices, v.result.vertices, name);
    assert.equal(report.triangles, v.result.triangles, name);
    // Every level by one range request, after the header and the head.
    const ranged = log.filter((e) => e.path.startsWith('/v/'));
    assert.equal(ranged.length, 2 + v.result.levels, JSON.stringify(ranged));
    assert.ok(ranged.every((e) => e.status === 206), JSON.stringify(ranged));
    // A frame per round at least, and the mesh fills part of the view.
    assert.ok(report.frames >= v.result.rounds, `${name}: ${report.frames} frames`);
    assert.ok(report.covered > 0.05 && report.covered < 0.95, `${name}: covers ${report.covered}`);
    console.log(`viewer: ${name}: ${report.triangles} triangles in ${report.frames} frames, ` +
      `${report.bytesFetched} bytes fetched, covers ${(100 * report.covered).toFixed(1)} % of the view`);
  }

  // Far away with the default screen error, the viewer stops early.
  {
    const v = vector('bunny-npm');
    await page.goto(`${url}/?stream=/v/${v.file}&pixels=1e9`);
    await page.waitForFunction(() => window.viewer.state === 'idle' || window.viewer.state === 'error',
      null, { timeout: 60_000 });
    const report = await page.evaluate(() => ({ ...window.viewer }));
    assert.equal(report.levelsDone, 1, JSON.stringify(report));
  }

  // A corrupt stream shows the decoder's error class.
  {
    const bad = manifest.vectors.find((x) => !x.valid && x.error_class === 'checksum-mismatch');
    await page.goto(`${url}/?stream=/v/${bad.file}&level=99`);
    await page.waitForFunction(() => window.viewer.state === 'error', null, { timeout: 60_000 });
    const error = await page.evaluate(() => window.viewer.error);
    assert.ok(error.startsWith('checksum-mismatch: '), error);
    assert.match(await page.textContent('#status'), /^error: checksum-mismatch/);
  }
  assert.deepEqual(errors, []);
  console.log('viewer: ok in headless Chromium');
} finally {
  await browser.close();
  server.close();
}
