// Unit tests of the page's pure modules (G-code reader, preview links, settings parsing,
// sample part, the discharge units, profiles, per-unit figures), bundled from www/core,
// www/views/form and www/worker with esbuild and run in Node.
import { after, before, test } from "node:test";
import assert from "node:assert/strict";
import { mkdtempSync, readFileSync, rmSync } from "node:fs";
import { tmpdir } from "node:os";
import { join } from "node:path";
import { pathToFileURL } from "node:url";
import { build } from "esbuild";
import { repo } from "./helpers.mjs";

const out = mkdtempSync(join(tmpdir(), "dropslice-units-"));
let gcode, share, form, sample, units, profiles, figures, forms, render, plot;
/** The core's job schema: a link's parts are checked against it. */
let jobSchema;
/** The core's own check of settings (what it reads a value as). */
let checkSettings;
/** The core's settings schema and its default settings. */
let schema, coreDefaults;

before(async () => {
  const names = ["worker/gcode", "core/share", "core/settings", "core/sample", "core/units", "core/profiles", "core/figures", "views/form", "views/canvas/render", "views/plot"];
  await build({
    entryPoints: names.map((n) => join(repo, "www", `${n}.ts`)),
    bundle: true,
    format: "esm",
    platform: "neutral",
    outdir: out,
    logLevel: "error",
  });
  [gcode, share, form, sample, units, profiles, figures, forms, render, plot] = await Promise.all(names.map((n) => import(pathToFileURL(join(out, `${n}.js`)).href)));
  // the G-code reader is the core's (built into www/pkg by the page build)
  await gcode.loadCore(readFileSync(join(repo, "www", "pkg", "dropslice_bg.wasm")));
  const core = await import(pathToFileURL(join(repo, "www", "pkg", "dropslice.js")).href);
  await core.default({ module_or_path: readFileSync(join(repo, "www", "pkg", "dropslice_bg.wasm")) });
  jobSchema = core.job_schema();
  checkSettings = core.check_settings;
  schema = core.settings_schema();
  coreDefaults = core.default_settings();
});

after(() => rmSync(out, { recursive: true, force: true }));

const HEADER = "; dropslice test\n; layer_height = 0.2 (mm)\n; droplet_aspect = 1.04\n; end of header\n";

function read(text) {
  const layers = [];
  const r = new gcode.GcodeReader((l) => layers.push(l));
  for (const line of text.split("\n")) r.line(line);
  r.finish();
  return { layers, reader: r };
}

test("G-code reader: G25 lines expand to droplets every B, layers split on Z", () => {
  const B = 0.2 * 1.04;
  const { layers, reader } = read(
    HEADER +
      "G26 X1.0000 Y1.0000 Z0.2000\nG26 X1.2080 Y1.0000 Z0.2000\n" +
      `G01 X0.0000 Y0.0000 Z0.2000\nG25 X${(10 * B).toFixed(4)} Y0.0000 Z0.2000\n` +
      "G26 X5.0000 Y5.0000 Z0.4000\n",
  );
  assert.equal(reader.dropletWidth, B);
  assert.equal(layers.length, 2);
  assert.deepEqual(layers[0].counts, { outer: 2, inner: 0, fill: 11, support: 0, units: [13, 0, 0, 0], parts: [13] });
  assert.equal(layers[0].roles.length, 13);
  assert.ok(Math.abs(layers[0].droplets[2 * 12] - 10 * B) < 1e-4, "last droplet at the line's end");
  assert.ok(Math.abs(layers[0].droplets[2 * 3] - B) < 1e-6, "second droplet one B along");
  assert.equal(layers[0].travel.length, 4);
  assert.equal(layers[1].z, 0.4);
  assert.equal(layers[1].counts.outer, 1);
});

test("G-code reader: after T1 droplets are unit 1's, every B₁ along a G25 line", () => {
  const B1 = 0.2 * 2.0;
  const { layers } = read(
    "; layer_height = 0.2\n; droplet_aspect = 1.0\n; unit1_droplet_aspect = 2.0\n" +
      "G26 X0.0000 Y0.0000 Z0.2000\nT1\nG01 X0.0000 Y1.0000 Z0.2000\n" +
      `G25 X${(3 * B1).toFixed(4)} Y1.0000 Z0.2000\nT0\nG26 X0.0000 Y2.0000 Z0.2000\n`,
  );
  assert.deepEqual([...layers[0].units], [0, 1, 1, 1, 1, 0]);
  assert.equal(layers[0].counts.units[1], 4);
  assert.deepEqual(layers[0].counts.parts, [2, 4], "each unit's droplets, from the droplets' units");
  assert.ok(Math.abs(layers[0].droplets[2 * 2] - B1) < 1e-4, "unit 1's droplets B₁ apart");
});

test("G-code reader: refuses files it cannot understand", () => {
  assert.throws(() => read("G26 X1 Y1 Z0.2\n"), /droplet size/);
  assert.throws(() => read(HEADER + "M104 S200\n"), /G-code for another kind of printer \(it has M104\)/);
  assert.throws(() => read(HEADER + "hello\n"), /not a G01, G25 or G26/);
  assert.throws(() => read(HEADER + "G26 X1 Yabc Z0.2\n"), /bad number/);
  assert.throws(() => read(HEADER + "G26 X1 Q2 Z0.2\n"), /unknown word/);
  assert.throws(() => read(HEADER), /no G01\/G25\/G26/);
});

test("preview links: base64url and deflate round trips, hash of bytes", async () => {
  const bytes = new Uint8Array(70_000).map((_, i) => (i * 31) % 256);
  assert.deepEqual(share.fromBase64Url(share.toBase64Url(bytes)), bytes);
  assert.doesNotMatch(share.toBase64Url(bytes), /[+/=]/);
  assert.deepEqual(await share.inflate(await share.deflate(bytes)), bytes);
  assert.equal(
    await share.sha256Hex(new TextEncoder().encode("abc")),
    "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad",
  );
});

test("preview links: embedded when small, hash only when big", async () => {
  const state = { settings: { contours: 3 }, layer: 7, view: { scale: 12, cx: 1, cy: 2 }, name: "p.stl", sha256: "ab" };
  const small = new Uint8Array(1000).fill(7);
  const a = await share.makeLink("http://x/#old", state, new Blob([small]));
  assert.ok(a.embedded && a.url.startsWith("http://x/#p="));
  const back = await share.readLink(a.url.slice(a.url.indexOf("#")), jobSchema);
  assert.deepEqual(back.state, state);
  assert.deepEqual(back.model, small);
  // random bytes do not compress: 300 KB stays above the 256 KB limit
  const big = new Uint8Array(300_000);
  for (let i = 0; i < big.length; i += 65536) crypto.getRandomValues(big.subarray(i, i + 65536));
  const b = await share.makeLink("http://x/", state, new Blob([big]));
  assert.equal(b.embedded, false);
  assert.doesNotMatch(b.url, /&m=/);
  assert.equal((await share.readLink(b.url.slice(b.url.indexOf("#")), jobSchema)).model, null);
  assert.equal(await share.readLink("#", jobSchema), null);
  await assert.rejects(share.readLink("#p=AAAA", jobSchema));
});

test("settings: relaxed input becomes strict values, with messages", () => {
  const spec = { name: "layer_height", kind: "number", unit: "mm", min: 0, max: 5, min_exclusive: true, choices: [], group: "g", description: "", default: 0.2 };
  assert.deepEqual(form.parse(spec, " 0,25 "), { value: 0.25 });
  assert.match(form.parse(spec, "0").error, /greater than 0 mm/);
  assert.match(form.parse(spec, "6").error, /at most 5 mm/);
  assert.match(form.parse(spec, "").error, /needed/);
  assert.match(form.parse(spec, "1e").error, /not a number/);
  const int = { ...spec, kind: "integer", min_exclusive: false, unit: "" };
  assert.match(form.parse(int, "2.5").error, /whole number/);
  assert.deepEqual(form.parse(int, "3"), { value: 3 });
  const en = { ...spec, kind: "enum", choices: ["a", "b"] };
  assert.deepEqual(form.parse(en, "b"), { value: "b" });
  assert.ok(form.parse(en, "c").error);
  assert.deepEqual(form.parse({ ...spec, kind: "bool" }, true), { value: true });
});

test("settings: an order of units reads as the core reads it, a choice or a list such as 2,0,1", () => {
  const spec = schema.find((s) => s.name === "unit_order");
  assert.equal(spec.kind, "order");
  const core = (text) => {
    try {
      return checkSettings({ units: 4, unit_order: text }).unit_order;
    } catch {
      return undefined;
    }
  };
  for (const text of ["unit0_first", "unit2_first", "1,2,0", " 2, 0 ,1 ", "3", "1,0", "0,1,2,3", "3,2,1,0", "2,0", "1,1", "4,0", "a", "", "1,,2", "-1", "1.5", "01", "+2", "2 0"]) {
    const mine = form.parse(spec, text);
    assert.equal(mine.value, core(text), `"${text}": the page reads ${JSON.stringify(mine)}`);
    if (mine.value === undefined) assert.match(mine.error, /such as 2,0,1/, `"${text}"`);
  }
});

test("sample part: a closed binary STL (every edge shared by exactly two facets, opposite ways)", () => {
  const { bytes, name } = sample.sampleStl();
  assert.match(name, /\.stl$/);
  const dv = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const n = dv.getUint32(80, true);
  assert.equal(bytes.length, 84 + 50 * n);
  const edges = new Map();
  const key = (o) => [0, 4, 8].map((k) => dv.getFloat32(o + k, true)).join(",");
  for (let f = 0; f < n; f++) {
    const o = 84 + 50 * f + 12;
    const v = [key(o), key(o + 12), key(o + 24)];
    for (let k = 0; k < 3; k++) {
      const e = `${v[k]}|${v[(k + 1) % 3]}`;
      edges.set(e, (edges.get(e) ?? 0) + 1);
    }
  }
  for (const [e, count] of edges) {
    const [a, b] = e.split("|");
    assert.equal(count, 1, `edge ${e} used ${count} times in one direction`);
    assert.equal(edges.get(`${b}|${a}`), 1, `edge ${e} has no opposite`);
  }
});

test("units: the count from the settings (2 without `units`), per-unit names, each unit's droplets", () => {
  assert.equal(units.unitsOf({}), 2, "a core without `units`: unit 0 and unit 1");
  assert.equal(units.unitsOf(null), 2);
  assert.equal(units.unitsOf({ units: 1 }), 1);
  assert.equal(units.unitsOf({ units: 4 }), 4);
  assert.equal(units.unitsOf({ units: 5 }), 2, "out of range: the default (the core refuses it)");
  assert.equal(units.unitsOf({ units: 2.5 }), 2);
  assert.deepEqual(units.unitIndices(3), [0, 1, 2]);
  assert.equal(units.unitOfSetting("unit1_droplet_aspect"), 1);
  assert.equal(units.unitOfSetting("unit3_shrink_xy"), 3);
  assert.equal(units.unitOfSetting("unit_order"), null);
  assert.equal(units.unitOfSetting("droplet_aspect"), null);
  assert.equal(units.unitSetting("droplet_aspect", 0), "droplet_aspect");
  assert.equal(units.unitSetting("droplet_aspect", 2), "unit2_droplet_aspect");
  assert.equal(units.plainSetting("unit2_material_density"), "material_density");
  assert.equal(units.supportUnit("unit2"), 2);
  assert.equal(units.supportUnit("off"), null);
  // roles 0–2 of units 0 … 2, support (role 3) left out whatever its unit
  const roles = Uint8Array.from([0, 1, 2, 3, 3, 0, 2, 1]);
  const us = Uint8Array.from([0, 0, 1, 1, 2, 2, 2, 0]);
  assert.deepEqual(units.partsByUnit(roles, us), [3, 1, 2]);
  assert.deepEqual(units.partsByUnit(Uint8Array.from([0, 3]), Uint8Array.from([0, 1])), [1], "support alone adds no unit");
  // the palette: four distinct colours; units 0 and 1 keep the page's two-unit colours
  assert.equal(new Set(units.UNIT_COLORS).size, 4);
  assert.equal(units.UNIT_COLORS[1], "#7048e8");
  assert.equal(units.UNIT_BARS[0], "#a5c8ec");
  assert.equal(units.UNIT_BARS[1], "#b9a7f4");
});

test("units: the form groups unitN_ rows under Unit N", () => {
  const row = (name, group) => ({ name, group });
  assert.equal(forms.groupOf(row("unit1_droplet_aspect", "Unit 1")), "Unit 1");
  assert.equal(forms.groupOf(row("unit2_droplet_aspect", "Units")), "Unit 2");
  assert.equal(forms.groupOf(row("droplet_aspect", "Droplet")), "Droplet");
  assert.equal(forms.groupOf(row("unit_order", "Unit 1")), "Unit 1");
  // every per-unit row of this core's schema lands in its unit's group
  for (const s of schema) if (units.unitOfSetting(s.name) !== null) assert.equal(forms.groupOf(s), `Unit ${units.unitOfSetting(s.name)}`);
});

test("units: each unit's figures from the core's per-unit entries", () => {
  const f = new figures.Figures();
  const unit = (droplets, volume_mm3, mass_g, seconds, predicted_density) => ({ droplets, volume_mm3, mass_g, seconds, predicted_density });
  // a machine of two units: a unit beyond the entries prints nothing
  f.core = { droplets: 100, print_seconds: 10, units: [unit(70, 5, 0.1, 7, 99), unit(30, 2, 0.05, 3, null)] };
  assert.deepEqual(f.units(2), [
    { droplets: 70, volume: 5, mass: 0.1, seconds: 7, density: 99 },
    { droplets: 30, volume: 2, mass: 0.05, seconds: 3, density: null },
  ]);
  assert.deepEqual(f.units(3)[2], { droplets: 0, volume: 0, mass: 0, seconds: 0, density: null });
  assert.deepEqual(f.units(1).map((u) => u.droplets), [70]);
  // the estimates are unit 0's material with the whole print time
  assert.deepEqual(f.estimates, { volume: 5, mass: 0.1, seconds: 10 });
  // three units: entries indexed by unit
  f.core = { droplets: 6, units: [unit(1, 1, 1, 4, null), unit(2, 1, 1, 5, 98), unit(3, 1, 1, 6, null)] };
  assert.deepEqual(f.units(3).map((u) => [u.droplets, u.seconds, u.density]), [[1, 4, null], [2, 5, 98], [3, 6, null]]);
  // a .gco file: each unit's droplets as read
  const g = new figures.Figures();
  g.addReadLayer({ counts: { outer: 2, inner: 0, fill: 3, support: 0, units: [4, 1, 0, 0], parts: [4, 1] }, travelMm: 0 });
  g.addReadLayer({ counts: { outer: 1, inner: 0, fill: 0, support: 0, units: [1, 0, 0, 0], parts: [1] }, travelMm: 0 });
  assert.deepEqual(g.units(2).map((u) => u.droplets), [5, 1]);
  assert.equal(g.units(2)[1].volume, null);
});

test("settings: the page's table is the core's (checkInit); what differs from the defaults is all a file keeps", () => {
  const settings = form;
  const init = settings.checkInit({ version: "test", schema, job: jobSchema, defaults: coreDefaults });
  assert.deepEqual(init.schema.map((s) => s.name), [...settings.SETTING_NAMES]);
  assert.deepEqual(Object.keys(settings.DEFAULTS), [...settings.SETTING_NAMES]);
  for (const s of schema) assert.equal(settings.DEFAULTS[s.name], s.default, s.name);
  // the core's settings as it writes them leave out `units` and units 2 and 3's own: their
  // defaults are the table's all the same
  for (const [k, v] of Object.entries(coreDefaults)) assert.equal(settings.DEFAULTS[k], v, k);
  assert.equal(init.defaults.units, 2);
  assert.equal(init.defaults.unit2_droplet_aspect, init.defaults.droplet_aspect);
  // a core of another build is refused, naming the setting
  const without = schema.filter((s) => s.name !== "fill_density");
  assert.throws(() => settings.checkInit({ version: "x", schema: without, job: jobSchema, defaults: coreDefaults }), /different builds.*fill_density/);
  const extra = [...schema, { ...schema[0], name: "new_setting" }];
  assert.throws(() => settings.checkInit({ version: "x", schema: extra, job: jobSchema, defaults: coreDefaults }), /different builds.*new_setting/);
  const changed = schema.map((s) => (s.name === "contours" ? { ...s, default: 3 } : s));
  assert.throws(() => settings.checkInit({ version: "x", schema: changed, job: jobSchema, defaults: coreDefaults }), /default of contours/);
  // a job file, a link and the remembered settings keep only what differs, in the table's order
  assert.deepEqual(settings.nonDefault({ ...settings.DEFAULTS }), {});
  const some = settings.nonDefault({ ...settings.DEFAULTS, units: 3, layer_height: 0.25, unit2_droplet_aspect: 1.2 });
  assert.deepEqual(Object.entries(some), [["layer_height", 0.25], ["units", 3], ["unit2_droplet_aspect", 1.2]]);
  assert.ok(settings.isSettingName("unit3_shrink_z") && !settings.isSettingName("unit4_shrink_z") && !settings.isSettingName("copies"));
});

test("profiles: a material profile holds one material, used for the unit picked; older ones with unit1_ keys as before", () => {
  const values = Object.fromEntries(schema.map((s) => [s.name, s.default]));
  values.droplet_aspect = 1.2;
  values.material_density = 1.1;
  values.unit1_droplet_aspect = 1.5;
  values.unit1_material_density = 1.3;
  // saved from unit 1: its values, no unit in the keys
  const p = profiles.profileOf("PC", "material", values, schema, 1);
  assert.ok(Object.keys(p.settings).length > 0);
  assert.ok(Object.keys(p.settings).every((k) => units.unitOfSetting(k) === null), JSON.stringify(p.settings));
  assert.equal(p.settings.droplet_aspect, 1.5);
  assert.equal(p.settings.material_density, 1.3);
  assert.equal(profiles.needsUnit(p), true);
  assert.deepEqual(profiles.checkProfile(JSON.parse(profiles.profileFileText(p)), schema), p, "it reads back");
  // used for unit 0, then for unit 1: that unit's names, nothing else
  const to0 = profiles.profileSettings(p, 0, schema);
  assert.deepEqual(to0.missing, []);
  assert.equal(to0.settings.droplet_aspect, 1.5);
  assert.ok(!("unit1_droplet_aspect" in to0.settings));
  const to1 = profiles.profileSettings(p, 1, schema);
  assert.equal(to1.settings.unit1_droplet_aspect, 1.5);
  assert.equal(to1.settings.unit1_material_density, 1.3);
  assert.ok(!("droplet_aspect" in to1.settings), "unit 0's material stays as it is");
  // a unit the core has no settings for is named, not set
  const to3 = profiles.profileSettings(p, 3, schema);
  if (!schema.some((s) => s.name === "unit3_droplet_aspect")) assert.ok(to3.missing.includes("unit3_droplet_aspect"));
  // a profile saved before: both units' keys, used as it is (no unit asked)
  const old = { name: "old", kind: "material", settings: { droplet_aspect: 1.1, unit1_droplet_aspect: 1.7, unit1_shrink_xy: 0.5 } };
  const checked = profiles.checkProfile(old, schema);
  assert.deepEqual(checked, old);
  assert.equal(profiles.needsUnit(checked), false);
  assert.deepEqual(profiles.profileSettings(checked, 1, schema).settings, old.settings);
  // a machine profile as before; a material key in it is still refused
  const m = profiles.profileOf("M", "machine", values, schema);
  assert.equal(profiles.needsUnit(m), false);
  assert.ok("plate_x" in m.settings);
  assert.equal(profiles.checkProfile({ name: "bad", kind: "machine", settings: { droplet_aspect: 1 } }, schema), null);
  assert.equal(profiles.checkProfile({ name: "bad", kind: "material", settings: { unit1_plate_x: 1 } }, schema), null);
});

test("units: each unit's colour class in the layer view and the cut, each unit's bar in the plot", () => {
  const { dropletClass, CLASS_COLORS, CLASS_ORDER } = render;
  // unit 0 by role, the support whatever its unit, units 1 … 3 a colour each
  assert.deepEqual([0, 1, 2].map((r) => dropletClass(r, 0)), [0, 1, 2]);
  assert.deepEqual([0, 1, 2, 3].map((u) => dropletClass(3, u)), [3, 3, 3, 3]);
  assert.deepEqual([1, 2, 3].map((u) => dropletClass(1, u)), [4, 5, 6]);
  assert.deepEqual([...CLASS_COLORS], ["#d9480f", "#f59f00", "#3b8fdd", "#1098ad", "#7048e8", "#6b4226", "#343a40"]);
  assert.deepEqual([...CLASS_ORDER].sort(), [0, 1, 2, 3, 4, 5, 6], "every class drawn once");
  // a layer's stack: each unit's parts, then the support; with fewer units shown than the
  // droplets name, the rest go to the last unit shown
  const c = { outer: 5, inner: 0, fill: 6, support: 4, units: [7, 6, 2, 0], parts: [7, 2, 2] };
  assert.deepEqual(plot.stackOf(c, 3), [7, 2, 2, 4]);
  assert.deepEqual(plot.stackOf(c, 4), [7, 2, 2, 0, 4]);
  assert.deepEqual(plot.stackOf(c, 2), [7, 4, 4]);
  assert.equal(plot.layerTotal(c), 15);
});
