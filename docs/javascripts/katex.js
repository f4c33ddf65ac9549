// Typeset the formulas that pymdownx.arithmatex (generic mode) wraps as \( ... \) and \[ ... \],
// with the KaTeX shipped in docs/vendor/katex (no CDN: the site works from disk and offline).
// Material's document$ fires on every page view, the first one included.
document$.subscribe(({ body }) => {
  renderMathInElement(body, {
    delimiters: [
      { left: "\\(", right: "\\)", display: false },
      { left: "\\[", right: "\\]", display: true },
    ],
    throwOnError: true,  // a formula KaTeX cannot read is an error in the console, which the tests fail on
  });
});
