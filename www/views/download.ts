// Saving the G-code: a file named after the model.

export function baseName(name: string): string {
  return name.replace(/\.[^.]*$/, "") || "model";
}

/** Hands `blob` to the browser as a download named `<model>.gco`. */
export function saveGcode(blob: Blob, modelName: string): void {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = `${baseName(modelName)}.gco`;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 60_000);
}
