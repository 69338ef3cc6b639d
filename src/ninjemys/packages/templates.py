"""The files ``catkin_create_pkg`` writes: package.xml (format 2) and a catkin-compatible CMakeLists.txt.

The CMakeLists.txt keeps the commented blocks the tutorials tell users to uncomment
(add_message_files, generate_messages, catkin_install_python); ninjemys does not need them but
accepts them, and a real catkin can still build the package.
"""

from __future__ import annotations

from xml.sax.saxutils import escape


def package_xml(
    name: str, deps: list[str], version: str, description: str, maintainer: str, email: str, license_: str
) -> str:
    dep_lines = []
    for kind in ("build_depend", "build_export_depend", "exec_depend"):
        dep_lines += [f"  <{kind}>{escape(d)}</{kind}>" for d in deps]
    body = "\n".join(dep_lines)
    return f"""<?xml version="1.0"?>
<package format="2">
  <name>{escape(name)}</name>
  <version>{escape(version)}</version>
  <description>{escape(description)}</description>

  <maintainer email="{escape(email)}">{escape(maintainer)}</maintainer>
  <license>{escape(license_)}</license>

  <!-- Messages: add <build_depend>message_generation</build_depend> and
       <exec_depend>message_runtime</exec_depend> for real catkin; ninjemys needs neither. -->
  <buildtool_depend>catkin</buildtool_depend>
{body}

  <export>
  </export>
</package>
"""


def cmakelists(name: str, deps: list[str]) -> str:
    components = "\n".join(f"  {d}" for d in deps)
    return f"""cmake_minimum_required(VERSION 3.0.2)
project({name})

## Find catkin macros and libraries
find_package(catkin REQUIRED COMPONENTS
{components}
)

## Uncomment if the package has a setup.py (Python modules under src/)
# catkin_python_setup()

## Messages, services and actions in msg/, srv/, action/
## (ninjemys generates them whether or not these lines are uncommented)
# add_message_files(
#   FILES
#   Message1.msg
# )
# add_service_files(
#   FILES
#   Service1.srv
# )
# generate_messages(
#   DEPENDENCIES
#   std_msgs
# )

catkin_package(
#  INCLUDE_DIRS include
#  LIBRARIES {name}
#  CATKIN_DEPENDS {" ".join(deps)}
#  DEPENDS system_lib
)

include_directories(
  ${{catkin_INCLUDE_DIRS}}
)

## Python scripts to install
# catkin_install_python(PROGRAMS
#   scripts/my_python_script
#   DESTINATION ${{CATKIN_PACKAGE_BIN_DESTINATION}}
# )
"""
