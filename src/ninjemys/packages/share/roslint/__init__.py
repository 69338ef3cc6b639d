"""roslint as shipped with ninjemys: package.xml and the CMake macros; the linters are ninjemys.tools.roslint."""
