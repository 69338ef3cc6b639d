"""Interface definitions: .msg/.srv/.action text -> typed spec -> md5/full text -> generated classes.

Modules: spec (the typed IR), parser, md5, fulltext, codegen (pure: spec -> Python source),
message (runtime base class), loader (compile once, lazy packages), search (where definitions live).
"""
