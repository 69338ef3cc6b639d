"""image_geometry as shipped with ninjemys: package.xml only (the module is src/image_geometry)."""
