// A setting's value as the page holds it, and the one place where the page's relaxed text input
// ("0,2", " 3 ") becomes the strict value the core expects (views/form.ts shows the result).

import type { SettingSpec } from "./protocol";

export type Value = number | boolean | string;

export function parse(spec: SettingSpec, raw: string | boolean): { value?: Value; error?: string } {
  if (spec.kind === "bool") return { value: Boolean(raw) };
  if (spec.kind === "enum") {
    return spec.choices.includes(String(raw)) ? { value: String(raw) } : { error: `choose one of ${spec.choices.join(", ")}` };
  }
  const text = String(raw).trim().replace(",", ".");
  if (text === "") return { error: "a value is needed" };
  const x = Number(text);
  if (!Number.isFinite(x)) return { error: `"${String(raw).trim()}" is not a number` };
  if (spec.kind === "integer" && !Number.isInteger(x)) return { error: "must be a whole number" };
  const unit = spec.unit ? ` ${spec.unit}` : "";
  if (spec.min !== null && (spec.min_exclusive ? x <= spec.min : x < spec.min)) {
    return { error: spec.min_exclusive ? `must be greater than ${spec.min}${unit}` : `must be at least ${spec.min}${unit}` };
  }
  if (spec.max !== null && x > spec.max) return { error: `must be at most ${spec.max}${unit}` };
  return { value: x };
}
