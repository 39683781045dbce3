// Debian's chromium driven by playwright-core, with every page's errors collected.
import { existsSync } from 'node:fs';
import { after, before } from 'node:test';
import { chromium } from 'playwright-core';
import { currentDaemon, DEFAULT_USER, startDaemon } from './daemon.js';

const CHROMIUM = '/usr/bin/chromium';

export async function launchBrowser() {
  if (!existsSync(CHROMIUM)) {
    throw new Error(`${CHROMIUM} is missing: run \`make deps-test\` to install Debian's chromium`);
  }
  return chromium.launch({
    executablePath: CHROMIUM,
    args: [
      '--headless',
      '--no-sandbox',
      '--disable-gpu',
      '--disable-quic',
      '--no-first-run',
      '--disable-background-networking',
      '--disable-component-update',
      '--disable-sync',
      '--use-angle=swiftshader',
      '--enable-unsafe-swiftshader',
    ],
  });
}

// A page in its own context, signed in as user (an admin account of that name, made on first
// use; "api" when none is named) on the daemon started last, unless token is given (null: not
// signed in); page.problems collects uncaught exceptions and console errors.
export async function openPage(browser, { user, token, viewport = { width: 1280, height: 800 } } = {}) {
  const context = await browser.newContext({ viewport });
  const t = token === undefined ? await currentDaemon().tokenFor(user ?? DEFAULT_USER) : token;
  if (t) {
    await context.addInitScript((value) => localStorage.setItem('archgram.token', value), t);
  }
  const page = await context.newPage();
  page.problems = [];
  page.on('pageerror', (err) => page.problems.push(`uncaught: ${err.stack || err.message}`));
  page.on('console', (msg) => {
    if (msg.type() === 'error') page.problems.push(`console.error: ${msg.text()}`);
  });
  return page;
}

// What a test file's tests share: one archgramd and one chromium, started before the first test
// and stopped after the last. env.daemon and env.browser are set once the tests run.
export function daemonAndBrowser() {
  const env = { daemon: null, browser: null };
  before(async () => {
    env.daemon = await startDaemon();
    env.browser = await launchBrowser();
  });
  after(async () => {
    if (env.browser) await env.browser.close();
    if (env.daemon) await env.daemon.stop();
  });
  return env;
}
