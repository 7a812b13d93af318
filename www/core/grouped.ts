// Grouping by a key, in the order the items come.

/** `items` grouped by `key`: each group's values (`value` of its items, the items themselves
 *  by default) in the items' order; the groups in the order their first item came. */
export function grouped<T, K, V = T>(items: Iterable<T>, key: (t: T) => K, value: (t: T) => V = (t) => t as unknown as V): Map<K, V[]> {
  const out = new Map<K, V[]>();
  for (const t of items) {
    const k = key(t);
    const list = out.get(k);
    if (list) list.push(value(t));
    else out.set(k, [value(t)]);
  }
  return out;
}

/** The records of a flat array of `stride` numbers each (a last, short one left out). */
export function* records(flat: Float64Array, stride: number): Generator<Float64Array> {
  for (let j = 0; j + stride <= flat.length; j += stride) yield flat.subarray(j, j + stride);
}
