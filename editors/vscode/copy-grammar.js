// copy-grammar.js: copies the repository's TextMate grammar (grammar/sdf.tmLanguage.json, the
// one the other editors read) into syntaxes/, where the extension's package.json names it.
// Run by `npm install` and before `npm run package`, so the extension never carries its own.
const fs = require("fs");
const path = require("path");

const source = path.join(__dirname, "..", "..", "grammar", "sdf.tmLanguage.json");
const target = path.join(__dirname, "syntaxes", "sdf.tmLanguage.json");
fs.mkdirSync(path.dirname(target), { recursive: true });
fs.copyFileSync(source, target);
