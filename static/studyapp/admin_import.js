// Import clips (admin): the collection field takes the uploaded zip's (else the manifest's) file name as a slug,
// like the server does when it is left blank, until the user types a name of their own.
(function () {
  "use strict";
  const form = document.getElementById("clip-import-form");
  if (!form) return;
  const field = form.querySelector("input[name=collection]");
  const uploads = ["archive", "manifest"].map((name) => form.querySelector(`input[name=${name}]`));
  let typed = field.value !== "";

  // django.utils.text.slugify of the name without its extension
  function slug(fileName) {
    const stem = fileName.replace(/\.[^.]*$/, "");
    return stem.normalize("NFKD").replace(/[^\x00-\x7f]/g, "").toLowerCase()
      .replace(/[^\w\s-]/g, "").replace(/[-\s]+/g, "-").replace(/^[-_]+|[-_]+$/g, "")
      .slice(0, Number(field.maxLength) > 0 ? field.maxLength : 40);
  }

  field.addEventListener("input", () => { typed = field.value !== ""; });
  for (const input of uploads) {
    if (!input) continue;
    input.addEventListener("change", () => {
      const chosen = uploads.find((u) => u && u.files.length);
      if (!typed && chosen) field.value = slug(chosen.files[0].name);
    });
  }
})();
