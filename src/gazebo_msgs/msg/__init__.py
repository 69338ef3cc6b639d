from ninjemys.idl.loader import package_module_hooks

__getattr__, __dir__ = package_module_hooks(__name__)
