// Navigation bar shared by every page: the pages this server offers, current one highlighted.
"use strict";
(async function buildNav() {
  const nav = document.getElementById("nav");
  try {
    const pages = await (await fetch("/api/pages")).json();
    for (const page of pages) {
      const a = document.createElement("a");
      a.href = page.path;
      a.textContent = page.title;
      const here = location.pathname === page.path || (page.path === "/" && location.pathname === "/graph");
      if (here) a.className = "current";
      nav.appendChild(a);
    }
  } catch (err) {
    console.warn("navigation unavailable", err);
  }
})();
