// Browser end-to-end test of `obscura serve`: Playwright (playwright-core) driving Debian's
// Chromium headless against tests/explore/scene.toml. Run through tests/explore/run.sh.
//
// Expectations are computed here from the scene's numbers and the conventions of
// docs/cameras.md (raster y down, screen y up, the fov spanning the smaller axis, camera +z
// along the view), not asked of the server.
import { chromium } from 'playwright-core';
import { spawn, spawnSync } from 'node:child_process';
import { mkdirSync, writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const here = dirname(fileURLToPath(import.meta.url));
const obscura = process.env.OBSCURA || join(here, '../../target/debug/obscura');
const browserPath = process.env.CHROMIUM || '/usr/bin/chromium';
const out = process.env.OUT || join(here, 'out');
mkdirSync(out, { recursive: true });
const scenePath = join(here, 'scene.toml');

// The scene (scene.toml).
const W = 160, H = 120, TAN = Math.tan((40 / 2) * Math.PI / 180), ASPECT = W / H;
const EYE = [0, 1, 6];
const RED = { c: [-1.2, 0.8, 2.0], r: 0.8 };
const BLUE = { c: [1.5, 1.5, -6.0], r: 1.5 };

// The world direction through raster (x, y), scaled so its camera-space z is 1: the camera
// looks along world -z with up +y, so camera x, y, z are world x, y, -z.
function direction(x, y) {
  const sx = (x / W) * 2 * ASPECT - ASPECT;
  const sy = 1 - (y / H) * 2;
  return [sx * TAN, sy * TAN, -1];
}
// Camera-space depth of the floor (y = 0) seen through raster (x, y).
function floorDepth(x, y) {
  const d = direction(x, y);
  return -EYE[1] / d[1];
}
// Camera-space depth of a sphere seen through raster (x, y), or null.
function sphereDepth(s, x, y) {
  const d = direction(x, y);
  const o = EYE.map((e, i) => e - s.c[i]);
  const a = d[0] ** 2 + d[1] ** 2 + d[2] ** 2;
  const b = 2 * (o[0] * d[0] + o[1] * d[1] + o[2] * d[2]);
  const c = o[0] ** 2 + o[1] ** 2 + o[2] ** 2 - s.r ** 2;
  const disc = b * b - 4 * a * c;
  return disc < 0 ? null : (-b - Math.sqrt(disc)) / (2 * a);
}
// Raster position of a world point (the inverse of `direction`).
function project(p) {
  const v = p.map((c, i) => c - EYE[i]);
  const z = -v[2];
  return [((v[0] / z / TAN + ASPECT) / (2 * ASPECT)) * W, ((1 - v[1] / z / TAN) / 2) * H];
}
// Raster radius of a sphere's silhouette (small-angle: r / distance in units of the fov).
function rasterRadius(s) {
  const dist = Math.hypot(...s.c.map((c, i) => c - EYE[i]));
  return (Math.tan(Math.asin(s.r / dist)) / TAN) * (H / 2);
}

let passed = 0, failed = 0;
function check(name, ok, detail = '') {
  if (ok) passed++; else failed++;
  console.log(`${ok ? 'ok' : 'FAILED'} - ${name}${detail ? ` (${detail})` : ''}`);
}

// Start the server on a free loopback port and read its URL.
const server = spawn(obscura, ['serve', scenePath, '--port', '0', '--threads', '2'], {
  stdio: ['ignore', 'pipe', 'inherit'],
});
const url = await new Promise((resolve, reject) => {
  let text = '';
  const timer = setTimeout(() => reject(new Error('no URL from obscura serve in 60 s')), 60000);
  server.stdout.on('data', (chunk) => {
    text += chunk;
    const m = text.match(/http:\/\/127\.0\.0\.1:\d+\//);
    if (m) { clearTimeout(timer); resolve(m[0]); }
  });
  server.on('exit', (code) => reject(new Error(`obscura serve exited with ${code}`)));
});
console.log(`# server at ${url}`);

const browser = await chromium.launch({ executablePath: browserPath, args: ['--no-sandbox'] });
try {
  const page = await browser.newPage({ viewport: { width: 1400, height: 900 } });
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(String(e)));
  const outside = [];
  page.on('request', (r) => { if (!r.url().startsWith(url) && !r.url().startsWith(url.replace('http', 'ws')) && !r.url().startsWith('blob:')) outside.push(r.url()); });
  await page.goto(url);

  // Waits for the last pass of a view newer than `after`, returns its pixels (RGBA bytes).
  async function finalFrame(after) {
    await page.waitForFunction((g) => {
      const s = window.explorer;
      return s.generation > g && s.frame.generation === s.generation && s.frame.pass === s.frame.passes;
    }, after, { timeout: 120000 });
    return page.evaluate(() => {
      const c = document.getElementById('view');
      return { gen: window.explorer.generation, px: Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data) };
    });
  }

  await page.waitForFunction(() => window.explorer.session !== null &&
    window.explorer.frame.generation === 0 && window.explorer.frame.pass === window.explorer.frame.passes,
    null, { timeout: 120000 });
  const first = await page.evaluate(() => {
    const c = document.getElementById('view');
    return { w: c.width, h: c.height, px: Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data) };
  });
  check('the first frame arrives at the scene resolution', first.w === W && first.h === H, `${first.w}x${first.h}`);
  await page.screenshot({ path: join(out, '1-first-frame.png') });

  // Click to focus: CSS position of a raster position on the canvas.
  async function clickRaster(x, y) {
    const box = await page.locator('#view').boundingBox();
    const gen = await page.evaluate(() => window.explorer.generation);
    await page.mouse.click(box.x + (x / W) * box.width, box.y + (y / H) * box.height);
    await page.waitForFunction((g) => window.explorer.generation > g, gen);
    return page.evaluate(() => ({ focus: window.explorer.focus, camera: window.explorer.camera }));
  }
  {
    const { focus, camera } = await clickRaster(80, 110);
    const want = floorDepth(focus.x, focus.y);
    check('focus on the floor: the depth is the floor\'s', Math.abs(focus.depth - want) < 1e-3 * want,
      `got ${focus.depth}, floor at ${want.toFixed(4)} for raster (${focus.x.toFixed(2)}, ${focus.y.toFixed(2)})`);
    check('focus on the floor: focal_distance is that depth', camera.focal_distance === focus.depth,
      `${camera.focal_distance}`);
  }
  // Focus near the red sphere's right edge, below the horizon (whose far floor blurs), so
  // that its silhouette there is in focus.
  const [rx, ry] = project(RED.c);
  const rr = rasterRadius(RED);
  let focusGen;
  {
    const { focus, camera } = await clickRaster(rx + 0.75 * rr, ry + 0.5 * rr);
    const want = sphereDepth(RED, focus.x, focus.y);
    check('focus on the near sphere: the depth is the sphere\'s', want !== null && Math.abs(focus.depth - want) < 1e-3 * want,
      `got ${focus.depth}, sphere at ${want} for raster (${focus.x.toFixed(2)}, ${focus.y.toFixed(2)})`);
    check('focus on the near sphere: focal_distance is that depth', camera.focal_distance === focus.depth);
    focusGen = await page.evaluate(() => window.explorer.generation);
  }
  const sharp = await finalFrame(focusGen - 1);

  // The lens-radius slider: the image changes, the far sphere's edge blurs, the focused
  // sphere's much less.
  await page.locator('#c-lens_radius').fill('0.15');
  const blurred = await finalFrame(sharp.gen);
  const radius = await page.evaluate(() => window.explorer.camera.lens_radius);
  check('the slider sets lens_radius', radius === 0.15, `${radius}`);
  await page.screenshot({ path: join(out, '2-lens.png') });

  let diff = 0;
  for (let i = 0; i < sharp.px.length; i++) diff += Math.abs(sharp.px[i] - blurred.px[i]);
  diff /= sharp.px.length;
  check('the image changes with the lens radius', diff > 0.5, `mean |difference| ${diff.toFixed(3)}`);

  // Squared horizontal gradients in a window across a silhouette's side edge: blur spreads
  // the step and lowers the sum.
  function edgeEnergy(px, cx, cy, half) {
    let e = 0;
    for (let y = Math.round(cy - 6); y <= Math.round(cy + 6); y++) {
      for (let x = Math.round(cx - half); x < Math.round(cx + half); x++) {
        for (let ch = 0; ch < 3; ch++) {
          const a = px[(y * W + x) * 4 + ch], b = px[(y * W + x + 1) * 4 + ch];
          e += (a - b) ** 2;
        }
      }
    }
    return e;
  }
  const [bx, by] = project(BLUE.c);
  // Side edges where the silhouette meets a plain background: black sky behind the far
  // sphere (0.6 radius above its centre), near floor behind the red one (0.5 below).
  const blueEdge = [bx - 0.8 * rasterRadius(BLUE), by - 0.6 * rasterRadius(BLUE)];
  const redEdge = [rx + Math.sqrt(0.75) * rr, ry + 0.5 * rr];
  const blueRatio = edgeEnergy(blurred.px, ...blueEdge, 12) / edgeEnergy(sharp.px, ...blueEdge, 12);
  const redRatio = edgeEnergy(blurred.px, ...redEdge, 8) / edgeEnergy(sharp.px, ...redEdge, 8);
  check('the far sphere\'s edge blurs', blueRatio < 0.5, `edge energy ratio ${blueRatio.toFixed(3)}`);
  // How much each edge moved: the mean change across the window, pinhole to lens. The
  // focused silhouette stays (a sub-pixel circle of confusion); the far one spreads ~10 px.
  function change(cx, cy, half) {
    let d = 0, n = 0;
    for (let y = Math.round(cy - 6); y <= Math.round(cy + 6); y++) {
      for (let x = Math.round(cx - half); x <= Math.round(cx + half); x++) {
        for (let ch = 0; ch < 3; ch++, n++) d += Math.abs(blurred.px[(y * W + x) * 4 + ch] - sharp.px[(y * W + x) * 4 + ch]);
      }
    }
    return d / n;
  }
  const redChange = change(...redEdge, 8), blueChange = change(...blueEdge, 12);
  check('the focused sphere\'s edge changes much less than the far one\'s', blueChange > 4 * redChange,
    `mean change at the focused edge ${redChange.toFixed(2)}, at the far edge ${blueChange.toFixed(2)} (of 255); ` +
    `edge energy ratios ${redRatio.toFixed(3)}, ${blueRatio.toFixed(3)}`);

  // The coordinates overlay under the pointer.
  const box = await page.locator('#view').boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.waitForFunction(() => document.getElementById('overlay').textContent.includes('NDC'));
  const overlay = await page.locator('#overlay').textContent();
  check('the overlay shows raster, NDC, screen and camera coordinates',
    ['raster', 'NDC', 'screen', 'camera'].every((w) => overlay.includes(w)), JSON.stringify(overlay));

  // Side by side with the post-process depth of field.
  await page.selectOption('#compare-mode', 'dof');
  await page.waitForFunction(() => { const i = document.getElementById('post'); return i.complete && i.naturalWidth > 0; }, null, { timeout: 120000 });
  const postSize = await page.evaluate(() => [document.getElementById('post').naturalWidth, document.getElementById('post').naturalHeight]);
  check('the post-process comparison shows', postSize[0] === W && postSize[1] === H, `${postSize}`);
  await page.mouse.move(box.x + box.width * 0.3, box.y + box.height * 0.6);
  await page.waitForTimeout(300);
  await page.screenshot({ path: join(out, '3-compare.png') });

  // Save the view as a scene file; `obscura check` accepts it.
  const session = await page.evaluate(() => window.explorer.session);
  const saved = await page.evaluate(async (s) => (await fetch(`/api/scene.toml?session=${s}`)).text(), session);
  const savedPath = join(out, 'saved-view.toml');
  writeFileSync(savedPath, saved);
  const checked = spawnSync(obscura, ['check', savedPath], { encoding: 'utf8' });
  check('obscura check accepts the saved view', checked.status === 0, (checked.stderr || '').trim());
  check('the saved view keeps the lens radius', /lens_radius\s*=\s*0\.15\b/.test(saved));
  const png = await page.evaluate(async (s) => {
    const r = await fetch(`/api/image.png?session=${s}`);
    return [r.status, new Uint8Array(await r.arrayBuffer()).slice(0, 4).join(',')];
  }, session);
  check('the image saves as PNG', png[0] === 200 && png[1] === '137,80,78,71', `${png}`);

  // A refused value: the page shows the server's message, naming the key.
  await page.evaluate(() => { document.getElementById('c-near').value = '-1'; });
  await page.locator('#c-near').dispatchEvent('change');
  await page.waitForFunction(() => (window.explorer.lastError || '').includes('camera.near'));
  check('a refused value is reported with its key', true);

  check('no page errors', pageErrors.length === 0, pageErrors.join('; '));
  check('no request leaves the server', outside.length === 0, outside.join(', '));
} catch (e) {
  check('the scenario ran to its end', false, e.stack || String(e));
} finally {
  await browser.close();
  server.kill('SIGTERM');
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
