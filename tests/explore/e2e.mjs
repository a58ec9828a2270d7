// Browser end-to-end test of `obscura serve`: Playwright (playwright-core) driving Debian's
// Chromium headless against tests/explore/scene.toml. Run through tests/explore/run.sh.
//
// Expectations are computed here from the scene's numbers and the conventions of
// docs/cameras.md (raster y down, screen y up, the fov spanning the smaller axis, camera +z
// along the view), not asked of the server.
import { chromium } from 'playwright-core';
import { spawn, spawnSync } from 'node:child_process';
import { mkdirSync, readFileSync, writeFileSync } from 'node:fs';
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
// Raster position of a world point (the inverse of `direction`); `zoom` > 1 for a screen
// window `zoom` times smaller than the default about the same centre.
function project(p, zoom = 1) {
  const v = p.map((c, i) => c - EYE[i]);
  const z = -v[2];
  const t = TAN / zoom;
  return [((v[0] / z / t + ASPECT) / (2 * ASPECT)) * W, ((1 - v[1] / z / t) / 2) * H];
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

// Starts `obscura serve` on a scene on a free loopback port: the process and its URL.
async function serve(scene) {
  const proc = spawn(obscura, ['serve', scene, '--port', '0', '--threads', '2'], {
    stdio: ['ignore', 'pipe', 'inherit'],
  });
  const address = await new Promise((resolve, reject) => {
    let text = '';
    const timer = setTimeout(() => reject(new Error('no URL from obscura serve in 60 s')), 60000);
    proc.stdout.on('data', (chunk) => {
      text += chunk;
      const m = text.match(/http:\/\/127\.0\.0\.1:\d+\//);
      if (m) { clearTimeout(timer); resolve(m[0]); }
    });
    proc.on('exit', (code) => reject(new Error(`obscura serve exited with ${code}`)));
  });
  return [proc, address];
}
const [server, url] = await serve(scenePath);
console.log(`# server at ${url}`);
const servers = [server];

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

  // The controls added for the rest of the scene format's [camera] keys. `setControl` types
  // into a field and waits for either the last pass of the new view or an error.
  async function setControl(key, text) {
    const id = 'c-' + key.replace('.', '-');
    const gen = await page.evaluate(() => { window.explorer.lastError = null; return window.explorer.generation; });
    await page.evaluate(([id, text]) => { document.getElementById(id).value = text; }, [id, text]);
    await page.locator('#' + id).dispatchEvent('change');
    await page.waitForFunction((g) => {
      const s = window.explorer;
      return s.lastError || (s.generation > g && s.frame.generation === s.generation && s.frame.pass === s.frame.passes);
    }, gen, { timeout: 120000 });
    return page.evaluate(() => {
      const c = document.getElementById('view');
      return { error: window.explorer.lastError, camera: window.explorer.camera,
        px: Array.from(c.getContext('2d').getImageData(0, 0, c.width, c.height).data) };
    });
  }
  function meanDiff(a, b) {
    let d = 0;
    for (let i = 0; i < a.length; i++) d += Math.abs(a[i] - b[i]);
    return d / a.length;
  }
  // The centroid of the blue sphere's pixels (blue well above red: not the grey floor, the
  // red sphere or the black sky) in columns x0..x1 of an image `width` wide.
  function blueCentroid(px, width = W, x0 = 0, x1 = W) {
    let sx = 0, sy = 0, n = 0;
    for (let y = 0; y < H; y++) {
      for (let x = x0; x < x1; x++) {
        const i = (y * width + x) * 4;
        if (px[i + 2] - px[i] > 60 && px[i + 2] > px[i + 1]) { sx += x + 0.5; sy += y + 0.5; n++; }
      }
    }
    return [sx / n, sy / n];
  }
  const near = (a, b, tol) => Math.hypot(a[0] - b[0], a[1] - b[1]) < tol;
  const fmt2 = (p) => `(${p[0].toFixed(2)}, ${p[1].toFixed(2)})`;
  {
    // A pinhole first, so the silhouettes are sharp.
    const lensGen = await page.evaluate(() => window.explorer.generation);
    await page.locator('#c-lens_radius').fill('0');
    const pinhole = await finalFrame(lensGen);
    const at = blueCentroid(pinhole.px), want = project(BLUE.c);
    check('the pinhole view puts the far sphere where the geometry says', near(at, want, 1.5),
      `centroid ${fmt2(at)}, projected centre ${fmt2(want)}`);

    // screen_window: 1.5 times smaller than the default [-4/3, 4/3, -1, 1], so the picture
    // zooms 1.5 times about its centre.
    const zoomed = await setControl('screen_window', '-0.8888889, 0.8888889, -0.6666667, 0.6666667');
    check('the screen_window control is taken', !zoomed.error && zoomed.camera.screen_window?.length === 4,
      zoomed.error || JSON.stringify(zoomed.camera.screen_window));
    const zat = blueCentroid(zoomed.px), zwant = project(BLUE.c, 1.5);
    check('screen_window zooms the render about its centre', meanDiff(pinhole.px, zoomed.px) > 2 && near(zat, zwant, 1.5),
      `mean |difference| ${meanDiff(pinhole.px, zoomed.px).toFixed(2)}; centroid ${fmt2(zat)}, projected centre ${fmt2(zwant)}`);
    await page.screenshot({ path: join(out, '4-screen-window.png') });
    const back = await setControl('screen_window', '');
    check('an emptied screen_window is removed', !back.error && !('screen_window' in back.camera) && meanDiff(pinhole.px, back.px) === 0,
      back.error || `mean |difference| from the pinhole ${meanDiff(pinhole.px, back.px)}`);

    // [camera.stereo]: keys of the sub-table; the page shows the pair as `obscura render`
    // lays it out. Side by side first: twice as wide, each half an eye.
    const pair = await setControl('stereo.convergence', '5');
    const size = () => page.evaluate(() => [document.getElementById('view').width, document.getElementById('view').height]);
    const notice = () => page.locator('#notice').textContent();
    const sbsSize = await size();
    check('the stereo controls set [camera.stereo]; the pair shows side by side', !pair.error &&
      pair.camera.stereo?.convergence === 5 && sbsSize.join('x') === `${2 * W}x${H}` && !(await notice()).includes('midway'),
      pair.error || `${JSON.stringify(pair.camera.stereo)}; canvas ${sbsSize}; notice ${JSON.stringify(await notice())}`);
    // Each eye moves by b/2 along camera x and its window shifts so that the convergence
    // plane (C = 5) lines up: a point at depth z is (H/2) b (1/z - 1/C) / tan(20 deg) pixels
    // further right in the left eye than in the right. The far sphere (z = 12) with b = 0.5:
    // 60 * 0.5 * (1/12 - 1/5) / 0.364 = -9.6 pixels, the left eye's image on the left.
    const B = 0.5, C = 5, Z = EYE[2] - BLUE.c[2];
    const parallax = (H / 2) * B * (1 / Z - 1 / C) / TAN;
    const [cx, cy] = project(BLUE.c);
    const wider = await setControl('stereo.interaxial', String(B));
    const left = blueCentroid(wider.px, 2 * W, 0, W), right = blueCentroid(wider.px, 2 * W, W, 2 * W);
    right[0] -= W;
    check('the interaxial restarts the render; each half is its eye, with the parallax of the rig',
      !wider.error && near(left, [cx + parallax / 2, cy], 1.5) && near(right, [cx - parallax / 2, cy], 1.5),
      wider.error || `left eye ${fmt2(left)}, right eye ${fmt2(right)}; predicted ${fmt2([cx + parallax / 2, cy])}, ${fmt2([cx - parallax / 2, cy])}`);
    await page.screenshot({ path: join(out, '7-stereo-side-by-side.png') });

    // Anaglyph: one image; red from the left eye, green and blue from the right. Above the
    // horizon and right of the red sphere only the far sphere is in front of the black sky,
    // so there the red channel's centroid is the left eye's sphere, the blue the right's.
    const ana = await setControl('stereo.layout', 'anaglyph');
    const anaSize = await size();
    function channelCentroid(px, ch) {
      let sx = 0, n = 0;
      for (let y = 30; y < 58; y++) {
        for (let x = 70; x < 135; x++) { const v = px[(y * W + x) * 4 + ch]; sx += v * (x + 0.5); n += v; }
      }
      return sx / n;
    }
    const red = channelCentroid(ana.px, 0), blue = channelCentroid(ana.px, 2);
    check('an anaglyph: red from the left eye, cyan from the right', !ana.error && anaSize.join('x') === `${W}x${H}` &&
      Math.abs(red - (cx + parallax / 2)) < 1.5 && Math.abs(blue - (cx - parallax / 2)) < 1.5,
      ana.error || `canvas ${anaSize}; red centroid ${red.toFixed(2)}, blue ${blue.toFixed(2)}; predicted ` +
      `${(cx + parallax / 2).toFixed(2)}, ${(cx - parallax / 2).toFixed(2)}`);
    await page.screenshot({ path: join(out, '8-stereo-anaglyph.png') });

    // Separate: shown side by side, the page says so, and the image saves one file per eye.
    const sep = await setControl('stereo.layout', 'separate');
    const sepSize = await size();
    const saves = await page.evaluate(async () => {
      const right = document.getElementById('save-png-right');
      const r = await fetch(right.href);
      const b = new Uint8Array(await r.arrayBuffer());
      const v = new DataView(b.buffer);
      return { hidden: right.hidden, left: document.getElementById('save-png').href, status: r.status,
        size: [v.getUint32(16), v.getUint32(20)] };
    });
    check('a separate pair shows side by side, says so, and saves each eye', !sep.error && sepSize.join('x') === `${2 * W}x${H}` &&
      (await notice()).includes('separate') && !saves.hidden && saves.left.includes('eye=left') && saves.status === 200 &&
      saves.size.join('x') === `${W}x${H}`, sep.error || `canvas ${sepSize}; ${JSON.stringify(saves)}; notice ${JSON.stringify(await notice())}`);

    // Emptied, the keys go one by one, and the table with the last.
    for (const key of ['stereo.layout', 'stereo.interaxial']) {
      const r = await setControl(key, '');
      check(`emptying ${key} removes it`, !r.error && !(key.split('.')[1] in (r.camera.stereo || {})), r.error || JSON.stringify(r.camera.stereo));
    }
    const single = await setControl('stereo.convergence', '');
    check('emptying the last stereo key removes [camera.stereo]', !single.error && !('stereo' in single.camera) &&
      meanDiff(pinhole.px, single.px) === 0, single.error || JSON.stringify(single.camera));

    // pose: the look-at's own matrix (world from camera: camera x, y, z along world x, y, -z,
    // at the eye) renders the same picture; the look-at keys go, since the pose is given one
    // way at a time.
    const posed = await setControl('pose', '1, 0, 0, 0,  0, 1, 0, 1,  0, 0, -1, 6,  0, 0, 0, 1');
    const eyeField = await page.locator('#c-eye').inputValue();
    check('the pose control replaces the look-at', !posed.error && posed.camera.pose?.length === 16 &&
      !('eye' in posed.camera) && eyeField === '', posed.error || `${JSON.stringify(posed.camera)}; eye field ${JSON.stringify(eyeField)}`);
    check('the look-at\'s matrix as pose renders the look-at\'s picture', meanDiff(pinhole.px, posed.px) < 0.05,
      `mean |difference| ${meanDiff(pinhole.px, posed.px).toFixed(4)}`);
    // rvec, tvec: OpenCV extrinsics (world -> OpenCV camera: x right, y down, z forward along
    // world x, -y, -z here): R a half turn about x, t = -R eye = (0, 1, 6): the same view again.
    const cv = await setControl('tvec', '0, 1, 6');
    check('the extrinsics controls replace the matrix, rvec filled in', !cv.error && !('pose' in cv.camera) &&
      JSON.stringify(cv.camera.rvec) === '[0,0,0]', cv.error || JSON.stringify(cv.camera));
    const turned = await setControl('rvec', String(Math.PI) + ', 0, 0');
    check('OpenCV extrinsics of the same view render the same picture', !turned.error && meanDiff(pinhole.px, turned.px) < 0.05,
      turned.error || `mean |difference| ${meanDiff(pinhole.px, turned.px).toFixed(4)}`);
    await page.screenshot({ path: join(out, '5-extrinsics.png') });
  }

  // A scene file beyond the explorer's limits is previewed at them, and the page says so.
  {
    const bigPath = join(out, 'beyond-the-limits.toml');
    writeFileSync(bigPath, readFileSync(scenePath, 'utf8')
      .replace('resolution = [160, 120]', 'resolution = [5000, 10]')
      .replace('spp = 16', 'spp = 10000000'));
    const [bigServer, bigUrl] = await serve(bigPath);
    servers.push(bigServer);
    const big = await browser.newPage({ viewport: { width: 1400, height: 900 } });
    big.on('pageerror', (e) => pageErrors.push(String(e)));
    await big.goto(bigUrl);
    await big.waitForFunction(() => window.explorer.frame.generation === 0, null, { timeout: 120000 });
    const seen = await big.evaluate(() => ({
      notice: document.getElementById('notice').textContent,
      w: document.getElementById('res-w').value, h: document.getElementById('res-h').value,
      spp: document.getElementById('spp').value,
      canvas: [document.getElementById('view').width, document.getElementById('view').height],
      passes: window.explorer.frame.passes,
    }));
    check('a scene beyond the limits is previewed at them', seen.w === '4096' && seen.h === '8' && seen.spp === '65536' &&
      seen.canvas.join('x') === '4096x8' && seen.passes === 65536, JSON.stringify({ ...seen, notice: undefined }));
    check('the page says which settings are previewed at the limits',
      ['film.resolution', '5000 x 10', '4096 x 8', 'sampler.spp', '10000000'].every((w) => seen.notice.includes(w)),
      JSON.stringify(seen.notice));
    await big.screenshot({ path: join(out, '6-beyond-the-limits.png') });
    await big.close();
  }

  check('no page errors', pageErrors.length === 0, pageErrors.join('; '));
  check('no request leaves the server', outside.length === 0, outside.join(', '));
} catch (e) {
  check('the scenario ran to its end', false, e.stack || String(e));
} finally {
  await browser.close();
  for (const s of servers) s.kill('SIGTERM');
}
console.log(`${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
