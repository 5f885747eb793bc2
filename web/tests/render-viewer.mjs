// Renders glint's viewer page in headless Chromium (Debian's chromium, driven by puppeteer-core)
// and saves the canvas as a PNG.
//
//   node web/tests/render-viewer.mjs --dir SITE | --url http://127.0.0.1:8000/
//        [--out shot.png] [--view shaded]
//        [--intrinsics fx,fy,cx,cy,w,h --world-to-camera m00,...,m33] [--exposure X]
//        [--background RRGGBB] [--check] [--timeout-s 120]
// (the camera parameters as the page's URL parameters, web/viewer/viewer.js)
//
// SITE is a static copy written by `glint view OUT --write-html SITE`; it is served here by a
// plain file server on 127.0.0.1 (a page's ES modules do not load from file://). --url loads the
// page from a running `glint view` instead. Prints one JSON
// line: the viewer's state, console errors, failed requests and the fraction of canvas pixels
// that differ from the background. --check exits 1 unless the scene loaded with no console error
// and drew something. Exit 77 (skipped) when Chromium or puppeteer-core is missing.
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { parseArgs } from 'node:util';

const SKIP = 77;
const { values: args } = parseArgs({
  options: {
    dir: { type: 'string' },
    url: { type: 'string' },
    out: { type: 'string' },
    view: { type: 'string', default: 'shaded' },
    intrinsics: { type: 'string' },
    'world-to-camera': { type: 'string' },
    exposure: { type: 'string' },
    background: { type: 'string' },
    check: { type: 'boolean', default: false },
    chromium: { type: 'string', default: process.env.CHROMIUM ?? '/usr/bin/chromium' },
    'timeout-s': { type: 'string', default: '120' },
  },
});
if (!args.dir === !args.url) {
  console.error('render-viewer: give --dir SITE (from `glint view OUT --write-html SITE`) or ' +
    '--url of a running `glint view`');
  process.exit(2);
}
if (!fs.existsSync(args.chromium)) {
  console.log(`render-viewer: skipped, no Chromium at ${args.chromium} (apt-get install chromium)`);
  process.exit(SKIP);
}
let puppeteer;
try {
  puppeteer = (await import('puppeteer-core')).default;
} catch {
  console.log('render-viewer: skipped, puppeteer-core missing (scripts/install-deps.sh installs web/node_modules)');
  process.exit(SKIP);
}

// A plain file server for --dir.
const types = { '.html': 'text/html', '.js': 'text/javascript', '.glb': 'model/gltf-binary',
  '.json': 'application/json', '.png': 'image/png' };
const site = path.resolve(args.dir ?? '.');
const server = http.createServer((request, response) => {
  const relative = decodeURIComponent(new URL(request.url, 'http://x').pathname);
  const file = path.join(site, relative.endsWith('/') ? `${relative}index.html` : relative);
  if (!file.startsWith(site + path.sep) || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
    response.writeHead(404).end();
    return;
  }
  response.writeHead(200, { 'Content-Type': types[path.extname(file)] ?? 'application/octet-stream' });
  fs.createReadStream(file).pipe(response);
});
if (args.dir) await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));

const query = new URLSearchParams({ view: args.view, clean: '1' });
if (args.intrinsics) query.set('intrinsics', args.intrinsics);
if (args['world-to-camera']) query.set('world_to_camera', args['world-to-camera']);
if (args.exposure) query.set('exposure', args.exposure);
if (args.background) query.set('background', args.background);
const base = args.url ?? `http://127.0.0.1:${server.address().port}/`;
const url = `${new URL('index.html', base)}?${query}`;

const profile = fs.mkdtempSync(path.join(os.tmpdir(), 'glint-chromium-'));
const browser = await puppeteer.launch({
  executablePath: args.chromium,
  headless: true,
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    // WebGL without a GPU: ANGLE on SwiftShader, the CPU rasteriser.
    '--use-angle=swiftshader', '--enable-unsafe-swiftshader', `--user-data-dir=${profile}`,
    '--window-size=1024,768'],
});
const result = { url, state: 'loading', console_errors: [], failed_requests: [] };
try {
  const page = await browser.newPage();
  page.on('console', (message) => {
    if (message.type() === 'error') result.console_errors.push(message.text());
  });
  page.on('pageerror', (error) => result.console_errors.push(String(error.message ?? error)));
  page.on('requestfailed', (request) => result.failed_requests.push(request.url()));
  page.on('response', (response) => {
    if (response.status() >= 400) result.failed_requests.push(`${response.status()} ${response.url()}`);
  });
  await page.setViewport({ width: 1024, height: 768 });
  await page.goto(url, { waitUntil: 'load', timeout: Number(args['timeout-s']) * 1000 });
  await page.waitForFunction(() => window.glintViewer && window.glintViewer.state !== 'loading',
    { timeout: Number(args['timeout-s']) * 1000, polling: 200 });
  Object.assign(result, await page.evaluate(() => {
    const { state, error, segments, lights, triangles } = window.glintViewer;
    return { state, error, segments, lights, triangles };
  }));
  if (result.state === 'ready') {
    // The canvas's own pixels (preserveDrawingBuffer), without the page around it.
    const shot = await page.evaluate(() => {
      const canvas = document.querySelector('canvas');
      const copy = document.createElement('canvas');
      copy.width = canvas.width;
      copy.height = canvas.height;
      const context = copy.getContext('2d');
      context.drawImage(canvas, 0, 0);
      const pixels = context.getImageData(0, 0, copy.width, copy.height).data;
      let drawn = 0;
      for (let i = 0; i < pixels.length; i += 4) {
        if (pixels[i] !== pixels[0] || pixels[i + 1] !== pixels[1] || pixels[i + 2] !== pixels[2]) ++drawn;
      }
      return { png: canvas.toDataURL('image/png'), width: copy.width, height: copy.height,
        drawn_fraction: drawn / (pixels.length / 4) };
    });
    result.width = shot.width;
    result.height = shot.height;
    result.drawn_fraction = shot.drawn_fraction;
    if (args.out) {
      fs.writeFileSync(args.out, Buffer.from(shot.png.split(',')[1], 'base64'));
      result.screenshot = args.out;
    }
  }
} catch (error) {
  result.state = 'error';
  result.error = String(error.message ?? error);
} finally {
  await browser.close();
  if (args.dir) server.close();
  fs.rmSync(profile, { recursive: true, force: true });
}
console.log(JSON.stringify(result));
if (args.check) {
  const problems = [];
  if (result.state !== 'ready') problems.push(`viewer state ${result.state}: ${result.error}`);
  if (result.console_errors.length) problems.push(`console errors: ${result.console_errors.join(' | ')}`);
  if (result.failed_requests.length) problems.push(`failed requests: ${result.failed_requests.join(' ')}`);
  if (!(result.drawn_fraction > 0.01)) problems.push(`only ${result.drawn_fraction} of the pixels drawn`);
  if (problems.length) {
    console.error(`render-viewer: ${problems.join('; ')}`);
    process.exit(1);
  }
}
