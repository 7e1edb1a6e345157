import { chromium } from "playwright-core";
const [url, out, waitMs] = process.argv.slice(2);
const browser = await chromium.launch({ executablePath: "/usr/bin/chromium", args: ["--no-sandbox", "--disable-gpu"] });
const page = await browser.newPage({ viewport: { width: 1280, height: 800 } });
const t0 = Date.now();
await page.goto(url);
const seen = [];
for (let i = 0; i < 40; i++) {
  await page.waitForTimeout(500);
  const s = await page.evaluate(() => document.body.innerText.slice(0, 200).replace(/\s+/g, " "));
  const f = await page.evaluate(() => window.__igi ? window.__igi.frames : -1);
  seen.push(`${Date.now() - t0}ms frames=${f} ${s.slice(0, 120)}`);
  if (f > 3) break;
}
console.log(seen.filter((_, i) => i % 4 == 0 || i == seen.length - 1).join("\n"));
await page.screenshot({ path: out });
await browser.close();
