"""diagnostic_updater as shipped with ninjemys: package.xml only (the module is src/diagnostic_updater)."""
