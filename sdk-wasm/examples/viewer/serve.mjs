// A static file server for the viewer that answers HTTP range requests
// (`python3 -m http.server` ignores them, so every level would download
// the whole file). For local use and the tests; not for production.
//
//   node sdk-wasm/examples/viewer/serve.mjs [--port 8000] [/prefix/=DIR ...]
//
// Without mounts it serves this folder at / (index.html, pkg/ once built
// there) and the current directory at /data/, so
// http://localhost:8000/?stream=/data/terrain.sps views ./terrain.sps.
import { createServer } from 'node:http';
import { createReadStream, statSync } from 'node:fs';
import { dirname, extname, join, normalize, resolve, sep } from 'node:path';
import { fileURLToPath } from 'node:url';

const TYPES = {
  '.html': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.wasm': 'application/wasm',
  '.json': 'application/json',
  '.css': 'text/css',
};

/**
 * Starts a server on `port` (0: any free one) serving each `mounts` entry
 * (URL prefix ending in `/` → folder). Resolves to `{ server, url, log }`,
 * `log` listing each request as `{ path, range, status, bytes }`.
 */
export function serve(mounts, port = 0) {
  const log = [];
  const prefixes = Object.keys(mounts).sort((a, b) => b.length - a.length);
  const server = createServer((req, res) => {
    const entry = { path: req.url, range: req.headers.range ?? null, status: 0, bytes: 0 };
    log.push(entry);
    const done = (status, headers = {}, body = '') => {
      entry.status = status;
      res.writeHead(status, headers);
      res.end(body);
    };
    if (req.method !== 'GET' && req.method !== 'HEAD') return done(405);
    const path = decodeURIComponent(new URL(req.url, 'http://x').pathname);
    const prefix = prefixes.find((p) => path.startsWith(p));
    if (prefix === undefined) return done(404);
    const dir = resolve(mounts[prefix]);
    let file = normalize(join(dir, path.slice(prefix.length)));
    if (file !== dir && !file.startsWith(dir + sep)) return done(403);
    let stat;
    try {
      stat = statSync(file);
      if (stat.isDirectory()) {
        file = join(file, 'index.html');
        stat = statSync(file);
      }
    } catch {
      return done(404);
    }
    const headers = {
      'Content-Type': TYPES[extname(file)] ?? 'application/octet-stream',
      'Accept-Ranges': 'bytes',
      'Cache-Control': 'no-store',
    };
    let [start, end] = [0, stat.size - 1];
    let status = 200;
    const range = /^bytes=(\d*)-(\d*)$/.exec(req.headers.range ?? '');
    if (req.headers.range !== undefined) {
      if (!range || (range[1] === '' && range[2] === '')) {
        return done(416, { 'Content-Range': `bytes */${stat.size}` });
      }
      if (range[1] === '') {
        start = Math.max(0, stat.size - Number(range[2])); // the last N bytes
      } else {
        start = Number(range[1]);
        if (range[2] !== '') end = Math.min(end, Number(range[2]));
      }
      if (start > end || start >= stat.size) {
        return done(416, { 'Content-Range': `bytes */${stat.size}` });
      }
      status = 206;
      headers['Content-Range'] = `bytes ${start}-${end}/${stat.size}`;
    }
    headers['Content-Length'] = end - start + 1;
    entry.status = status;
    entry.bytes = req.method === 'HEAD' ? 0 : end - start + 1;
    res.writeHead(status, headers);
    if (req.method === 'HEAD') return res.end();
    createReadStream(file, { start, end }).pipe(res);
  });
  return new Promise((ok, fail) => {
    server.once('error', fail);
    server.listen(port, '127.0.0.1', () => {
      ok({ server, url: `http://127.0.0.1:${server.address().port}`, log });
    });
  });
}

if (process.argv[1] && resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = process.argv.slice(2);
  let port = 8000;
  const mounts = {};
  for (let i = 0; i < args.length; i++) {
    if (args[i] === '--port') port = Number(args[++i]);
    else {
      const at = args[i].indexOf('=');
      if (at < 1 || !args[i].startsWith('/') || !args[i].slice(0, at).endsWith('/')) {
        console.error(`usage: serve.mjs [--port N] [/prefix/=DIR ...]; bad argument '${args[i]}'`);
        process.exit(2);
      }
      mounts[args[i].slice(0, at)] = args[i].slice(at + 1);
    }
  }
  if (Object.keys(mounts).length === 0) {
    mounts['/'] = dirname(fileURLToPath(import.meta.url));
    mounts['/data/'] = process.cwd();
  }
  const { url } = await serve(mounts, port);
  for (const [prefix, dir] of Object.entries(mounts)) console.log(`${url}${prefix} -> ${dir}`);
}
