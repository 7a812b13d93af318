// Hostile model files in the page (issue 22): an OBJ whose face corners are separated by
// vertical tabs (20 million + 1 triangles in one face: counted as tobj splits words, refused
// before it is built) and a 3MF whose vertex has a 15-million-digit number (the message quotes
// 80 characters of it). For each: a short banner within seconds, a page that keeps answering,
// and a good model opens after. Inputs are made here, at run time.
import { test } from "node:test";
import assert from "node:assert/strict";
import { crc32, deflateRawSync } from "node:zlib";
import { answers, pick, settleAnswering, startForTests, waitDone } from "./helpers.mjs";

const env = startForTests();

/** A ZIP archive of deflated entries ({ name, data }). */
function zip(entries) {
  const locals = [];
  const central = [];
  let offset = 0;
  for (const { name, data } of entries) {
    const packed = deflateRawSync(data);
    const n = Buffer.from(name);
    // The fields a local header and its central directory entry share (version needed,
    // method, CRC, sizes, name length) stand at 4 in the one and at 6 in the other.
    const shared = (buf, at) => {
      buf.writeUInt16LE(20, at);
      buf.writeUInt16LE(8, at + 4);
      buf.writeUInt32LE(crc32(data), at + 10);
      buf.writeUInt32LE(packed.length, at + 14);
      buf.writeUInt32LE(data.length, at + 18);
      buf.writeUInt16LE(n.length, at + 22);
      return buf;
    };
    const head = shared(Buffer.alloc(30), 4);
    head.writeUInt32LE(0x04034b50, 0);
    const dir = shared(Buffer.alloc(46), 6);
    dir.writeUInt32LE(0x02014b50, 0);
    dir.writeUInt16LE(20, 4);
    dir.writeUInt32LE(offset, 42);
    locals.push(head, n, packed);
    central.push(dir, n);
    offset += head.length + n.length + packed.length;
  }
  const size = central.reduce((s, b) => s + b.length, 0);
  const end = Buffer.alloc(22);
  end.writeUInt32LE(0x06054b50, 0);
  end.writeUInt16LE(entries.length, 8);
  end.writeUInt16LE(entries.length, 10);
  end.writeUInt32LE(size, 12);
  end.writeUInt32LE(offset, 16);
  return Buffer.concat([...locals, ...central, end]);
}

function verticalTabObj() {
  const corners = 20_000_000 + 3;
  const head = Buffer.from("v 0 0 0\nv 1 0 0\nv 0 1 0\nf");
  const buf = Buffer.alloc(head.length + 2 * corners + 1);
  head.copy(buf);
  for (let k = 0; k < corners; k++) {
    buf[head.length + 2 * k] = 0x0b;
    buf[head.length + 2 * k + 1] = 0x31 + (k % 3);
  }
  buf[buf.length - 1] = 0x0a;
  return buf;
}

function hugeAttribute3mf() {
  const rels = `<?xml version="1.0"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>`;
  const model = `<?xml version="1.0"?><model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02"><resources><object id="1"><mesh><vertices><vertex x="${"9".repeat(15_000_000)}" y="0" z="0"/></vertices></mesh></object></resources><build><item objectid="1"/></build></model>`;
  return zip([
    { name: "_rels/.rels", data: Buffer.from(rels) },
    { name: "3D/3dmodel.model", data: Buffer.from(model) },
  ]);
}

/** Waits, polling that the page answers, until it has settled; returns its status. */
const settle = (page, timeout) => settleAnswering(page, { timeout, states: ["done", "error", "cancelled"] });

/** A page of its own, collecting page errors, once it has settled on the sample. */
async function settledPage() {
  const context = await env.browser.newContext({ viewport: { width: 1280, height: 800 } });
  const page = await context.newPage();
  const errors = [];
  page.on("pageerror", (e) => errors.push(String(e)));
  await page.goto(env.url);
  await settle(page);
  return { context, page, errors };
}

const CASES = [
  ["an OBJ face of 20 M triangles split by vertical tabs", "tabs.obj", verticalTabObj, /20000001 triangles/],
  ["a 3MF vertex with a 15 MB number", "huge.3mf", hugeAttribute3mf, /not a finite number \('9{20,80}…'\)/],
];

test("hostile model files: a short banner within seconds, the page keeps answering", async () => {
  const { context, page, errors } = await settledPage();
  for (const [what, name, make, expected] of CASES) {
    const buffer = make();
    const t0 = Date.now();
    await pick(page, { name, mimeType: "application/octet-stream", buffer });
    // (Handing the page 40 MB through the test's browser connection takes seconds itself.)
    const t1 = Date.now();
    const s = await settle(page, 30_000);
    const seconds = (Date.now() - t1) / 1000;
    const handing = (t1 - t0) / 1000;
    assert.equal(s.state, "error", `${what}: ${JSON.stringify(s)}`);
    const text = await page.locator("#banner-message").innerText();
    assert.match(text, expected, `${what}: ${text.slice(0, 300)}`);
    assert.ok(text.length < 600, `${what}: the banner holds ${text.length} characters`);
    for (let i = 0; i < 3; i++) {
      await answers(page);
      await page.waitForTimeout(100);
    }
    console.log(`# ${what} (${(buffer.length / 1e6).toFixed(1)} MB, handed over in ${handing.toFixed(1)} s): refused in ${seconds.toFixed(1)} s, banner ${text.length} characters`);
  }
  // A good model still opens.
  await pick(page, {
    name: "cube.obj",
    mimeType: "text/plain",
    buffer: Buffer.from("v 0 0 0\nv 10 0 0\nv 10 10 0\nv 0 10 0\nv 0 0 10\nv 10 0 10\nv 10 10 10\nv 0 10 10\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n"),
  });
  await waitDone(page, 60_000);
  assert.deepEqual(errors, []);
  await context.close();
});

/** A 3MF of about a kilobyte that fans out 10^levels inside-out 0.5 mm cubes by components
 *  (as scripts/many_parts.py `fan`): one cube object, then `levels` objects of ten
 *  components each, 1 mm apart along x, y, z, then 10 mm, … */
function fannedCubes3mf(levels) {
  const rels = `<?xml version="1.0"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships"><Relationship Target="/3D/3dmodel.model" Id="rel0" Type="http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel"/></Relationships>`;
  let vertices = "";
  for (let i = 0; i < 8; i++) vertices += `<vertex x="${(i & 1) * 0.5}" y="${((i >> 1) & 1) * 0.5}" z="${((i >> 2) & 1) * 0.5}"/>`;
  const faces = [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]];
  // inside out: every triangle's corners in the other order
  const triangles = faces.map(([a, b, c]) => `<triangle v1="${a}" v2="${c}" v3="${b}"/>`).join("");
  let resources = `<object id="1" type="model"><mesh><vertices>${vertices}</vertices><triangles>${triangles}</triangles></mesh></object>`;
  for (let l = 0; l < levels; l++) {
    const axis = l % 3;
    const pitch = 10 ** Math.floor(l / 3);
    let components = "";
    for (let k = 0; k < 10; k++) {
      const t = [0, 1, 2].map((a) => (a === axis ? k * pitch : 0));
      components += `<component objectid="${l + 1}" transform="1 0 0 0 1 0 0 0 1 ${t.join(" ")}"/>`;
    }
    resources += `<object id="${l + 2}" type="model"><components>${components}</components></object>`;
  }
  const model = `<?xml version="1.0"?><model unit="millimeter" xmlns="http://schemas.microsoft.com/3dmanufacturing/core/2015/02"><resources>${resources}</resources><build><item objectid="${levels + 1}"/></build></model>`;
  return zip([
    { name: "_rels/.rels", data: Buffer.from(rels) },
    { name: "3D/3dmodel.model", data: Buffer.from(model) },
  ]);
}

test("10,000 inside-out cubes fanned out by a 1 KB 3MF: turned outward and sliced, the page answering", async () => {
  const { context, page, errors } = await settledPage();
  const buffer = fannedCubes3mf(4);
  assert.ok(buffer.length < 2000, `${buffer.length} bytes`);
  const t0 = Date.now();
  await pick(page, { name: "fanned.3mf", mimeType: "application/octet-stream", buffer });
  const s = await settle(page, 120_000);
  assert.equal(s.state, "done", JSON.stringify(s));
  // every cube printed: two or three layers of one loop of six or seven droplets each
  // (a plane can fall on a cube's top face, which counts as above it)
  assert.ok(s.droplets >= 10_000 * 12 && s.droplets <= 10_000 * 21, `${s.droplets} droplets`);
  const warnings = await page.evaluate(() => document.body.innerText);
  assert.match(warnings, /10,?000 closed shells were inside out/);
  console.log(`# 10,000 fanned cubes: ${s.droplets} droplets in ${((Date.now() - t0) / 1000).toFixed(1)} s`);
  assert.deepEqual(errors, []);
  await context.close();
});
