// Saving files: the G-code (named after the model) and the job file.

export function baseName(name: string): string {
  return name.replace(/\.[^.]*$/, "") || "model";
}

/** Hands `blob` to the browser as a download named `<model>.gco` (`<model>-and-N-more.gco`
 *  for a job of several files). */
export function saveGcode(blob: Blob, modelName: string, more = 0): void {
  saveFile(blob, `${baseName(modelName)}${more > 0 ? `-and-${more}-more` : ""}.gco`);
}

/** Hands `blob` to the browser as a download named `name`. */
export function saveFile(blob: Blob, name: string): void {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 60_000);
}
