// The built-in sample part, generated as a binary STL: a 20 x 20 x 12 mm block with a round
// through hole (Ø 8 mm) and a round boss (Ø 14 mm, 6 mm high) around the hole on top.
// Lower layers show an outer loop, loops around a hole and fill; upper layers a ring.
// Every surface is a band between two closed curves sampled at the same angles, so the
// mesh is closed and 2-manifold by construction.

const N = 96; // samples per curve, a multiple of 4 so the square's corners are samples

type P2 = [number, number];

function curve(fn: (c: number, s: number) => P2): P2[] {
  const out: P2[] = [];
  for (let i = 0; i < N; i++) {
    const t = Math.PI / 4 + (2 * Math.PI * i) / N;
    out.push(fn(Math.cos(t), Math.sin(t)));
  }
  return out;
}

export function sampleStl(): { name: string; bytes: Uint8Array } {
  const a = 10; // half side of the block
  const holeR = 4;
  const bossR = 7;
  const h1 = 12;
  const h2 = 18;
  const square = curve((c, s) => {
    const m = Math.max(Math.abs(c), Math.abs(s));
    return [a + (a * c) / m, a + (a * s) / m];
  });
  const circle = (r: number) => curve((c, s) => [a + r * c, a + r * s]);
  const hole = circle(holeR);
  const boss = circle(bossR);

  const tris: number[][] = [];
  const tri = (p: P2, pz: number, q: P2, qz: number, r: P2, rz: number) =>
    tris.push([p[0], p[1], pz, q[0], q[1], qz, r[0], r[1], rz]);
  type V = [P2, number];
  // the quad a b c d (counter-clockwise seen from its front), or seen from its back (flip)
  const quad = (a: V, b: V, c: V, d: V, flip: boolean) => {
    if (flip) {
      tri(...a, ...c, ...b);
      tri(...a, ...d, ...c);
    } else {
      tri(...a, ...b, ...c);
      tri(...a, ...c, ...d);
    }
  };
  // flat band between outer curve P and inner curve Q at height z; up = normal +z
  const ring = (P: P2[], Q: P2[], z: number, up: boolean) => {
    for (let i = 0; i < N; i++) {
      const j = (i + 1) % N;
      quad([Q[i], z], [P[i], z], [P[j], z], [Q[j], z], !up);
    }
  };
  // vertical wall along curve P from z0 to z1; out = normal away from the axis
  const wall = (P: P2[], z0: number, z1: number, out: boolean) => {
    for (let i = 0; i < N; i++) {
      const j = (i + 1) % N;
      quad([P[i], z0], [P[j], z0], [P[j], z1], [P[i], z1], !out);
    }
  };
  ring(square, hole, 0, false);
  wall(square, 0, h1, true);
  ring(square, boss, h1, true);
  wall(boss, h1, h2, true);
  ring(boss, hole, h2, true);
  wall(hole, 0, h2, false);
  return { name: "sample-block-with-boss.stl", bytes: binaryStl("dropslice sample: block with hole and boss", tris) };
}

/** Writes facets (9 numbers each) as a binary STL with normals from the winding. */
export function binaryStl(header: string, tris: number[][]): Uint8Array {
  const buf = new ArrayBuffer(84 + 50 * tris.length);
  const bytes = new Uint8Array(buf);
  bytes.set(new TextEncoder().encode(header.slice(0, 80)));
  const dv = new DataView(buf);
  dv.setUint32(80, tris.length, true);
  let o = 84;
  for (const t of tris) {
    const ux = t[3] - t[0], uy = t[4] - t[1], uz = t[5] - t[2];
    const vx = t[6] - t[0], vy = t[7] - t[1], vz = t[8] - t[2];
    let nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    const l = Math.hypot(nx, ny, nz) || 1;
    nx /= l; ny /= l; nz /= l;
    for (const v of [nx, ny, nz, ...t]) {
      dv.setFloat32(o, v, true);
      o += 4;
    }
    dv.setUint16(o, 0, true);
    o += 2;
  }
  return bytes;
}
