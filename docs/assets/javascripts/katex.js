// Typeset the $...$ and $$...$$ that pymdownx.arithmatex (generic mode) wraps, on every page load
// (document$ also fires on instant navigation in the material theme).
document$.subscribe(({ body }) => {
  renderMathInElement(body, {
    delimiters: [
      { left: "$$", right: "$$", display: true },
      { left: "$", right: "$", display: false },
      { left: "\\(", right: "\\)", display: false },
      { left: "\\[", right: "\\]", display: true },
    ],
    throwOnError: false,
  });
});
