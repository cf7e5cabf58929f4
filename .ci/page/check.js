// Opens every report.html under the directory given (default
// target/page-check) in headless Chromium (Debian's, /usr/bin/chromium, or
// $CHROMIUM) and checks, for each page:
// - no console errors, no uncaught exceptions, no network request (the page
//   must stand alone: everything is inline or a data: URI);
// - every plot decoded (each <figure> image has a size);
// - the verdict at the top; the listing opened (every line), its line lit
//   for the player's block; clicking the worst place (a plot's mark, else
//   a figure's row) takes the slider to its block; the first run of an
//   expansion's table (a cycle's, a loop's, a call's moves) named over the
//   listing when its row is clicked;
// - the 3-D view loaded scene.glb and drew it: a screenshot of the viewer,
//   kept beside the page as <name>.png, with pixels other than the
//   background over at least 1% of the view and in the middle, where the
//   camera points (the middle of the part);
// and that the viewer pilgrim inlines is byte for byte the pinned npm
// release (package.json).
// Run: npm ci --prefix .ci/page && node .ci/page/check.js target/page-check
"use strict";
const fs = require("fs");
const path = require("path");
const puppeteer = require("puppeteer-core");
const { PNG } = require("pngjs");

const root = process.argv[2] || "target/page-check";
const chromium = process.env.CHROMIUM || "/usr/bin/chromium";
// The viewer's background (model-viewer { background: #20262e }).
const BACKGROUND = [0x20, 0x26, 0x2e];

function pages(dir) {
  if (!fs.existsSync(dir)) return [];
  return fs.readdirSync(dir, { withFileTypes: true }).flatMap((e) => {
    const p = path.join(dir, e.name);
    if (e.isDirectory()) return pages(p);
    return e.name.endsWith(".html") ? [p] : [];
  });
}

function drawn(png) {
  const differs = (x, y) => {
    const i = (png.width * y + x) << 2;
    return BACKGROUND.some((c, k) => Math.abs(png.data[i + k] - c) > 12);
  };
  let all = 0;
  for (let y = 0; y < png.height; y++) {
    for (let x = 0; x < png.width; x++) all += differs(x, y) ? 1 : 0;
  }
  let centre = 0;
  const [cx, cy, h] = [png.width >> 1, png.height >> 1, 7];
  for (let y = cy - h; y <= cy + h; y++) {
    for (let x = cx - h; x <= cx + h; x++) centre += differs(x, y) ? 1 : 0;
  }
  return { share: all / (png.width * png.height), centre: centre / (2 * h + 1) ** 2 };
}

async function check(browser, file) {
  const problems = [];
  const page = await browser.newPage();
  await page.setViewport({ width: 1200, height: 900 });
  page.on("console", (m) => {
    if (m.type() === "error") problems.push("console error: " + m.text());
  });
  page.on("pageerror", (e) => problems.push("uncaught: " + e.message));
  await page.setRequestInterception(true);
  page.on("request", (r) => {
    const url = r.url();
    if (url.startsWith("data:") || url.startsWith("blob:") || url === "file://" + file) {
      r.continue();
    } else {
      problems.push("network request: " + url.slice(0, 120));
      r.abort();
    }
  });
  await page.goto("file://" + file, { waitUntil: "load" });
  const figures = await page.$$eval("figure img", (imgs) =>
    imgs.map((i) => [i.alt, i.naturalWidth > 0 && i.naturalHeight > 0])
  );
  for (const [alt, ok] of figures) if (!ok) problems.push("plot not drawn: " + alt);
  let view = "no 3-D view";
  if (await page.$("model-viewer")) {
    await page
      .waitForFunction(() => document.body.dataset.model, { timeout: 120000 })
      .catch(() => problems.push("scene.glb never loaded (120 s)"));
    const state = await page.evaluate(() => document.body.dataset.model);
    if (state !== "loaded") problems.push("3-D view: " + state);
    // Let the viewer render a few frames at rest.
    await page.evaluate(
      () => new Promise((ok) => requestAnimationFrame(() => requestAnimationFrame(() => setTimeout(ok, 500))))
    );
    const shot = file.replace(/\.html$/, ".png");
    const el = await page.$("model-viewer");
    await el.screenshot({ path: shot });
    const d = drawn(PNG.sync.read(fs.readFileSync(shot)));
    view = `3-D view ${(100 * d.share).toFixed(1)}% drawn, middle ${(100 * d.centre).toFixed(0)}% (${path.basename(shot)})`;
    if (d.share < 0.01) problems.push("the 3-D view is blank");
    if (d.centre < 0.5) problems.push("nothing drawn where the camera points");
    // The player: the slider at its start, middle and end puts the
    // program's bodies in three places, the viewer at each key's time.
    if (await page.$("#scrub")) {
      const shots = [];
      const max = await page.$eval("#scrub", (s) => +s.max);
      for (const i of [0, max >> 1, max]) {
        const ok = await page.evaluate((i) => {
          const s = document.getElementById("scrub");
          s.value = i;
          s.dispatchEvent(new Event("input"));
          const keys = JSON.parse(document.getElementById("keys").textContent);
          const mv = document.getElementById("scene");
          return Math.abs(mv.currentTime - keys[i][1]) < 1e-3;
        }, i);
        if (!ok) problems.push(`player: the viewer is not at key ${i}'s time`);
        await page.evaluate(
          () => new Promise((ok) => requestAnimationFrame(() => requestAnimationFrame(() => setTimeout(ok, 300))))
        );
        const png = file.replace(/\.html$/, `-key${i}.png`);
        await el.screenshot({ path: png });
        shots.push(PNG.sync.read(fs.readFileSync(png)));
      }
      const differ = (a, b) => {
        let n = 0;
        for (let k = 0; k < a.data.length; k += 4)
          if (Math.abs(a.data[k] - b.data[k]) + Math.abs(a.data[k + 1] - b.data[k + 1]) + Math.abs(a.data[k + 2] - b.data[k + 2]) > 24) n++;
        return n / (a.width * a.height);
      };
      const d1 = differ(shots[0], shots[1]), d2 = differ(shots[1], shots[2]);
      view += `; player: ${max + 1} keys, the bodies moved ${(100 * d1).toFixed(1)}% and ${(100 * d2).toFixed(1)}% of the view`;
      if (d1 < 0.001 || d2 < 0.001) problems.push("player: the view did not change along the program");
      // Clicking the nearest pair's row (or, on a machine with no pair to
      // check, the first pass's) takes the slider to the first key at or
      // after its block.
      const which = (await page.$("#clearances tr[data-block]"))
        ? "#clearances tr[data-block]"
        : "tr[data-block]";
      const row = await page.$(which);
      if (row) {
        await row.click();
        const went = await page.evaluate((which) => {
          const keys = JSON.parse(document.getElementById("keys").textContent);
          const b = +document.querySelector(which).dataset.block;
          const i = +document.getElementById("scrub").value;
          const want = keys.findIndex((k) => k[2] >= b);
          return [i, want < 0 ? keys.length - 1 : want, b];
        }, which);
        if (went[0] !== went[1]) problems.push(`player: the nearest pair's row (block ${went[2] + 1}) took the slider to key ${went[0]}, not ${went[1]}`);
        else view += `; a row of block ${went[2] + 1} took it to key ${went[0]}`;
      } else problems.push("player: no row that names a block");
      // The worst place: a verification's mark over its plot (or, where
      // it draws none, the verdict's figure that names a block) takes the
      // slider to its block, and the listing lights that block's line.
      const target = (await page.$(".marks .place")) ? ".marks .place" : "#figures tr[data-block]";
      const worst = await page.$(target);
      if (worst) {
        await worst.click();
        await page.evaluate(() => new Promise((ok) => requestAnimationFrame(() => setTimeout(ok, 100))));
        const went = await page.evaluate((target) => {
          const keys = JSON.parse(document.getElementById("keys").textContent);
          const b = +document.querySelector(target).dataset.block;
          const i = +document.getElementById("scrub").value;
          const want = keys.findIndex((k) => k[2] >= b);
          const now = document.querySelector("#listing .rows .now");
          const pane = document.getElementById("listing").getBoundingClientRect();
          const lit = now && now.getBoundingClientRect();
          const shown = +document.getElementById("listing").dataset.block === b;
          return [i, want < 0 ? keys.length - 1 : want, b, lit ? now.textContent : null, shown && lit ? lit.top >= pane.top && lit.bottom <= pane.bottom : false];
        }, target);
        if (went[0] !== went[1]) problems.push(`player: the worst place (block ${went[2] + 1}) took the slider to key ${went[0]}, not ${went[1]}`);
        else if (!went[4]) problems.push(`listing: block ${went[2] + 1}'s line not lit in view`);
        else view += `; the worst place (${target.startsWith(".marks") ? "a plot's mark" : "a figure"}, block ${went[2] + 1}) took it to key ${went[0]}, listing at "${went[3].trim().slice(0, 40)}"`;
      } else if (await page.$(".banner.unverified")) {
        view += "; not verified: no worst place";
      } else problems.push("player: no worst place to click");
      // A line of the listing clicked takes the slider to its block.
      // (By the mouse where the line stands: the pane redraws its lines as
      // the player moves, so a handle to one would not last.)
      const line = await page.evaluate(() => {
        // From the last key, so that any line before it moves the slider.
        const s = document.getElementById("scrub");
        s.value = s.max;
        s.dispatchEvent(new Event("input"));
        const pane = document.getElementById("listing");
        pane.scrollIntoView({ block: "center" });
        pane.scrollTop = Math.max(0, pane.scrollTop - 100);
        const r = pane.getBoundingClientRect();
        const [x, y] = [r.left + 30, r.top + r.height / 3];
        const d = document.elementFromPoint(x, y);
        return d && d.dataset.line ? [x, y, +d.dataset.line] : null;
      });
      await page.evaluate(() => new Promise((ok) => requestAnimationFrame(() => setTimeout(ok, 50))));
      if (line) {
        const before = await page.$eval("#scrub", (s) => +s.value);
        await page.mouse.click(line[0], line[1]);
        const after = await page.$eval("#scrub", (s) => +s.value);
        const block = await page.$eval("#listing", (p) => +p.dataset.block);
        if (before === after) problems.push(`listing: line ${line[2]} left the slider at key ${after}`);
        view += `; listing line ${line[2]} (block ${block + 1}) took it from key ${before} to ${after}`;
      } else problems.push("listing: no line drawn");
      // A run the reading expanded (a cycle, a loop, a call): its row takes
      // the player to its first block, and the line over the listing names
      // where that move was read from.
      const run = await page.$("table.expanded tr[data-block]");
      if (run) {
        await run.click();
        await page.evaluate(() => new Promise((ok) => requestAnimationFrame(() => setTimeout(ok, 50))));
        const named = await page.evaluate(() => {
          const row = document.querySelector("table.expanded tr[data-block]");
          return [row.cells[2].textContent, document.getElementById("source").textContent];
        });
        if (!named[1].includes(named[0])) problems.push(`source: the first expanded run ("${named[0]}") named "${named[1]}" over the listing`);
        else view += `; an expanded run's row named "${named[1]}"`;
      }
    }
    // The verdict at the top, seen without scrolling.
    const top = await page.$eval("#verdict", (b) => b.getBoundingClientRect().top + window.scrollY);
    if (top > 200) problems.push(`the verdict stands ${top} px down the page`);
  }
  await page.close();
  console.log(
    `${problems.length ? "FAIL" : "ok  "} ${file}: ${figures.length} plots, ${view}` +
      (problems.length ? "\n     " + problems.join("\n     ") : "")
  );
  return problems.length === 0;
}

(async () => {
  let failed = 0;
  const vendored = path.join(__dirname, "../../kernel/assets/model-viewer/model-viewer.min.js");
  const release = require.resolve("@google/model-viewer/dist/model-viewer.min.js");
  if (!fs.readFileSync(vendored).equals(fs.readFileSync(release))) {
    console.log("FAIL kernel/assets/model-viewer/model-viewer.min.js is not the pinned release's");
    failed++;
  }
  const files = pages(root).map((f) => path.resolve(f));
  if (files.length === 0) {
    console.log("page: no report.html under " + root);
    process.exit(1);
  }
  const browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    args: ["--no-sandbox", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"],
  });
  for (const f of files) {
    try {
      if (!(await check(browser, f))) failed++;
    } catch (e) {
      console.log(`FAIL ${f}: ${e.message}`);
      failed++;
    }
  }
  await browser.close();
  console.log(`page: ${files.length - failed} passed, ${failed} failed`);
  process.exit(failed ? 1 : 0);
})();
