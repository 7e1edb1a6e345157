// Memory probe of `igi serve` (issue 35, high 1): one page sends N refused messages, each naming
// a view (or a scene) of 15.5 KB that does not exist, then the server's resident memory is read
// from /proc, before and after the page closes. Not a test: the figures of ARCHITECTURE.md's
// "A refusal goes to the viewer that caused it" come from it.
//
// Usage (from this folder, after `npm ci`): node refusal_memory.mjs URL PID N view|open
// where PID is the process of `igi serve` listening at URL, e.g.
//   igi serve cornell-box --converge-frames 1 --listen 127.0.0.1:8617 &
//   node refusal_memory.mjs http://127.0.0.1:8617/ $! 30000 view

import { chromium } from "playwright-core";
import fs from "node:fs";

const [url, pid, n, type] = process.argv.slice(2);
if (!url || !pid || !n || !["view", "open"].includes(type)) {
  throw new Error("usage: node refusal_memory.mjs URL PID N view|open");
}
const rss = () => (Number(fs.readFileSync(`/proc/${pid}/status`, "utf8").match(/VmRSS:\s+(\d+)/)[1]) / 1024).toFixed(1);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", args: ["--no-sandbox", "--disable-gpu"] });
const page = await browser.newPage();
// The page itself watches, so the server renders as it does for a user.
await page.goto(url);
await sleep(3000);
console.log(`before: ${rss()} MB`);
const start = Date.now();
await page.evaluate(async ({ n, type }) => {
  const ws = new WebSocket(`ws://${location.host}/ws`);
  await new Promise((r) => { ws.onopen = r; });
  const name = "v".repeat(15500);
  const text = JSON.stringify({ input: { type, name } });
  for (let i = 0; i < n; i++) ws.send(text);
  while (ws.bufferedAmount > 0) await new Promise((r) => setTimeout(r, 20));
  window.__probe = ws;
}, { n: Number(n), type });
console.log(`sent ${n} ${type} messages in ${Date.now() - start} ms`);
await sleep(3000);
console.log(`after: ${rss()} MB`);
await page.close();
await sleep(2000);
console.log(`after the page closed: ${rss()} MB`);
await browser.close();
