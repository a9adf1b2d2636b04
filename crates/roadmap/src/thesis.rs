//! The thesis's published planning figures (§5.5.3 Tables 5.3–5.11, §6.1–6.2 Tables 6.1,
//! 6.2, 6.4), with their line references, so every program that prints our results beside
//! the thesis's reads them from one place.
