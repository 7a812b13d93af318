// What the flows and views share: the store, the worker pool, the canvas renderer, the 3D tab
// and the settings form (set once the core's schema has arrived). main.ts makes the one instance.

import type { Pool } from "./client";
import type { SettingsForm } from "./form";
import type { InitResult } from "./protocol";
import type { Renderer } from "./render";
import type { Store } from "./store";
import type { PartsPanel } from "./views/parts";
import type { View3DPanel } from "./views/view3d";

export interface Page {
  readonly store: Store;
  readonly pool: Pool;
  readonly renderer: Renderer;
  /** The stage's 3D tab. */
  readonly view3d: View3DPanel;
  /** The parts panel (left column). */
  readonly parts: PartsPanel;
  /** The settings form, once init has answered. */
  form?: SettingsForm;
  /** The core's version, settings schema and defaults, once init has answered. */
  init?: InitResult;
  /** The unit fix's button was pressed: scale the parts by `factor` and slice again. */
  onUnitFix(factor: number): void;
}
