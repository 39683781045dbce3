// Raw HTTP clients from a chosen loopback address (Linux routes all of 127/8 to lo), for the
// limits per client address: a whole health request, and a request that is never finished.
import net from 'node:net';
import { performance } from 'node:perf_hooks';

// GET /api/v1/health from localAddress; resolves with { status line, ms }.
export function healthFrom(port, localAddress) {
  return new Promise((resolve, reject) => {
    const t0 = performance.now();
    const s = net.connect({ port, host: '127.0.0.1', localAddress }, () => {
      s.write('GET /api/v1/health HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n');
    });
    let got = '';
    s.on('data', (b) => { got += b; });
    s.on('end', () => resolve({ head: got.split('\r\n')[0], ms: performance.now() - t0 }));
    s.on('error', reject);
  });
}

// A socket from localAddress that sends the start of a request and never its end; its
// closedAt is set when the server (or anything) closes it.
export function partialRequest(port, localAddress) {
  return new Promise((resolve) => {
    const s = net.connect({ port, host: '127.0.0.1', localAddress });
    s.on('error', () => {});
    s.on('connect', () => { s.write('GET /api/v1/health HTTP/1.1\r\nHost: x\r\n'); resolve(s); });
    s.on('close', () => { s.closedAt = Date.now(); });
    setTimeout(() => resolve(s), 3000);
  });
}
