# Bash completion for the ninjemys commands (ROS 1 in pure Python).
#
# Enable it with one of
#   eval "$(ninjemys-completion)"                  # in ~/.bashrc, after a pip install
#   source "$(python3 -m ninjemys.tools.complete --path)"
# (a catkin_make workspace's devel/setup.bash sources this file too).
#
# Subcommands and options are completed here; names from the live graph (topics, nodes, services,
# parameters), types, packages, executables and launch files come from
# `python -m ninjemys.tools.complete KIND [ARG...] PREFIX`, which makes one master call at most.
# The interpreter is $NINJEMYS_PYTHON, else the one `eval "$(ninjemys-completion)"` recorded, else
# the one named by the `#!` line of the rostopic on PATH, else python3.

# -- plumbing ------------------------------------------------------------------------------------

# sets _nj_py to the interpreter that runs the helper (no subshell: every fork is felt on a Tab press)
_nj_python() {
  if [[ -n ${NINJEMYS_PYTHON:-} ]]; then
    _nj_py=$NINJEMYS_PYTHON
    return
  fi
  if [[ -z ${_NJ_PY:-} ]]; then
    local script line
    script=$(type -P rostopic 2>/dev/null)
    if [[ -n $script ]] && IFS= read -r line <"$script" && [[ $line == '#!'*python* ]]; then
      line=${line#'#!'}
      line=${line#"${line%%[![:space:]]*}"}
      _NJ_PY=${line%%[[:space:]]*}
    else
      _NJ_PY=python3
    fi
  fi
  _nj_py=$_NJ_PY
}

# `python -c` rather than `-m`: runpy's imports would add a third to every answer
_NJ_HELPER='from ninjemys.tools.complete import main; raise SystemExit(main())'
# the directory holding the ninjemys package, when this file sits inside it: the helper then runs
# with `python -S` (no site-packages scan, no .pth hooks) and this directory as its only addition
if [[ -z ${_NJ_ROOT:-} && ${BASH_SOURCE[0]:-} == */ninjemys/share/completion/ninjemys.bash ]]; then
  _NJ_ROOT=${BASH_SOURCE[0]%/ninjemys/share/completion/ninjemys.bash}
fi
_NJ_FAST_HELPER='import sys; sys.path.insert(0, sys.argv.pop(1)); '$_NJ_HELPER

# _nj_run KIND [ARG...]: run the helper; the prototypes need PyYAML from site-packages, the rest
# needs the standard library only
_nj_run() {
  _nj_python
  if [[ -n ${_NJ_ROOT:-} && $1 != *-proto ]]; then
    "$_nj_py" -S -c "$_NJ_FAST_HELPER" "$_NJ_ROOT" "$@" 2>/dev/null
  else
    "$_nj_py" -c "$_NJ_HELPER" "$@" 2>/dev/null
  fi
}

# _nj_ask KIND [ARG...]: candidates from the helper, one per line, into COMPREPLY (prefix = $_nj_cur)
_nj_ask() {
  mapfile -t COMPREPLY < <(_nj_run "$@" "$_nj_cur")
  _nj_nospace_dirs
}

# _nj_ask_one KIND ARG: a single multi-line candidate (a YAML prototype) into COMPREPLY
_nj_ask_one() {
  local reply
  reply=$(_nj_run "$1" "$2" "")
  COMPREPLY=()
  if [[ -n $reply && $reply == "$_nj_cur"* ]]; then
    COMPREPLY=("$reply")
  fi
}

# _nj_words "WORD..." : the static words that start with $_nj_cur
_nj_words() {
  local word
  COMPREPLY=()
  for word in $1; do
    if [[ $word == "$_nj_cur"* ]]; then COMPREPLY+=("$word"); fi
  done
}

# _nj_files [EXT...]: file names (only *.EXT, plus directories, when extensions are given)
_nj_files() {
  compopt -o filenames 2>/dev/null
  if [[ $# -eq 0 ]]; then
    mapfile -t COMPREPLY < <(compgen -f -- "$_nj_cur")
    return
  fi
  local ext
  COMPREPLY=()
  mapfile -t -O "${#COMPREPLY[@]}" COMPREPLY < <(compgen -d -- "$_nj_cur")
  for ext in "$@"; do
    mapfile -t -O "${#COMPREPLY[@]}" COMPREPLY < <(compgen -f -X "!*.$ext" -- "$_nj_cur")
  done
}

# no space after a directory (pkg/sub/) or an argument assignment (name:=), so typing goes on
_nj_nospace_dirs() {
  local reply
  for reply in "${COMPREPLY[@]}"; do
    if [[ $reply == */ || $reply == *:= ]]; then
      compopt -o nospace 2>/dev/null
      return
    fi
  done
}

# _nj_parse "OPTS-TAKING-A-VALUE": sets
#   _nj_cur    the word being completed
#   _nj_pos    the positional words before it (options and their values left out)
#   _nj_optval the option whose value is being completed ("" if none)
_nj_parse() {
  local value_opts=" $1 " word i only_positional=0
  _nj_cur=${COMP_WORDS[COMP_CWORD]}
  _nj_pos=()
  _nj_optval=""
  for ((i = 1; i < COMP_CWORD; i++)); do
    word=${COMP_WORDS[i]}
    if ((only_positional)) || [[ $word != -* || $word == - ]]; then
      _nj_pos+=("$word")
    elif [[ $word == -- ]]; then
      only_positional=1
    elif [[ $value_opts == *" $word "* ]]; then
      if ((i + 1 == COMP_CWORD)); then
        _nj_optval=$word
      fi
      ((i++))
    fi
  done
}

# sets _nj_sub to the first word after the command that is not an option: the subcommand
_nj_subcommand() {
  local i
  _nj_sub=""
  for ((i = 1; i < COMP_CWORD; i++)); do
    if [[ ${COMP_WORDS[i]} != -* ]]; then
      _nj_sub=${COMP_WORDS[i]}
      return
    fi
  done
}

# ROS 1 command-line remappings and special arguments every node accepts
_NJ_NODE_ARGS="__name:= __ns:= __log:= __ip:= __hostname:= __master:="

# -- rostopic ------------------------------------------------------------------------------------

_rostopic() {
  local sub opts="" values=""
  _nj_subcommand
  sub=$_nj_sub
  case $sub in
    echo) opts="-h --help -b -p -w --filter --nostr --noarr -c --clear -a --all -n --offset --queue-size"
      values="-b -w --filter -n --queue-size" ;;
    list) opts="-h --help -b -v --verbose -p -s --host"; values="-b" ;;
    pub) opts="-h --help -v -r -1 --once -f -l --latch -s --substitute-keywords"; values="-r -f" ;;
    hz) opts="-h --help -w --filter --wall-time --tcpnodelay"; values="-w --filter" ;;
    bw) opts="-h --help -w"; values="-w" ;;
    delay) opts="-h --help -w --tcpnodelay"; values="-w" ;;
    info | type | find) opts="-h --help" ;;
  esac
  _nj_parse "$values"
  case $_nj_optval in
    -b) _nj_files bag; return ;;
    -f) _nj_files; return ;;
    "") ;;
    *) COMPREPLY=(); return ;;
  esac
  if [[ $_nj_cur == -* && -n $sub ]]; then
    _nj_words "$opts"
    return
  fi
  if ((${#_nj_pos[@]} == 0)); then
    _nj_words "bw delay echo find hz info list pub type"
    return
  fi
  case $sub:${#_nj_pos[@]} in
    echo:1 | hz:* | bw:* | delay:1 | info:1 | type:1 | list:1) _nj_ask topics ;;
    pub:1) _nj_ask topics ;;
    pub:2)
      _nj_ask topic-type "${_nj_pos[1]}"
      if ((${#COMPREPLY[@]} == 0)); then _nj_ask msgs; fi
      ;;
    pub:3) _nj_ask_one msg-proto "${_nj_pos[2]}" ;;
    find:1) _nj_ask msgs ;;
    *) COMPREPLY=() ;;
  esac
}

# -- rosnode -------------------------------------------------------------------------------------

_rosnode() {
  local sub opts="" values=""
  _nj_subcommand
  sub=$_nj_sub
  case $sub in
    list) opts="-h --help -u -a --all" ;;
    info) opts="-h --help -q --quiet" ;;
    ping) opts="-h --help -a --all -c"; values="-c" ;;
    kill) opts="-h --help -a --all" ;;
    machine | cleanup) opts="-h --help" ;;
  esac
  _nj_parse "$values"
  if [[ -n $_nj_optval ]]; then COMPREPLY=(); return; fi
  if [[ $_nj_cur == -* && -n $sub ]]; then
    _nj_words "$opts"
    return
  fi
  if ((${#_nj_pos[@]} == 0)); then
    _nj_words "cleanup info kill list machine ping"
    return
  fi
  case $sub in
    info | kill | ping) _nj_ask nodes ;;
    list) if ((${#_nj_pos[@]} == 1)); then _nj_ask nodes; fi ;;
    *) COMPREPLY=() ;;
  esac
}

# -- rosservice ----------------------------------------------------------------------------------

_rosservice() {
  local sub opts="-h --help"
  _nj_subcommand
  sub=$_nj_sub
  case $sub in
    list) opts="-h --help -n --nodes" ;;
    call) opts="-h --help -v --wait" ;;
  esac
  _nj_parse ""
  if [[ $_nj_cur == -* && -n $sub ]]; then
    _nj_words "$opts"
    return
  fi
  if ((${#_nj_pos[@]} == 0)); then
    _nj_words "args call find info list type uri"
    return
  fi
  case $sub:${#_nj_pos[@]} in
    args:1 | call:1 | info:1 | type:1 | uri:1 | list:1) _nj_ask services ;;
    call:2) _nj_ask_one srv-proto "${_nj_pos[1]}" ;;
    find:1) _nj_ask srvs ;;
    *) COMPREPLY=() ;;
  esac
}

# -- rosparam ------------------------------------------------------------------------------------

_rosparam() {
  local sub opts="-h --help -v" values=""
  _nj_subcommand
  sub=$_nj_sub
  case $sub in
    get) opts="-h --help -p -v" ;;
    set) opts="-h --help -t -b -v"; values="-t -b" ;;
  esac
  _nj_parse "$values"
  if [[ -n $_nj_optval ]]; then _nj_files; return; fi
  if [[ $_nj_cur == -* && -n $sub ]]; then
    _nj_words "$opts"
    return
  fi
  if ((${#_nj_pos[@]} == 0)); then
    _nj_words "delete dump get list load set"
    return
  fi
  case $sub:${#_nj_pos[@]} in
    get:1 | set:1 | delete:1 | list:1) _nj_ask params ;;
    load:1) _nj_files yaml yml ;;
    dump:1) _nj_files ;;
    load:2 | dump:2) _nj_ask params ;;
    *) COMPREPLY=() ;;
  esac
}

# -- rosmsg / rossrv -----------------------------------------------------------------------------

_nj_interface_tool() { # KIND (msg|srv)
  local kind=$1 sub opts="-h --help"
  _nj_subcommand
  sub=$_nj_sub
  case $sub in
    show | info) opts="-h --help -r --raw -b" ;;
    package | packages) opts="-h --help -s" ;;
  esac
  _nj_parse "-b"
  if [[ $_nj_optval == -b ]]; then _nj_files bag; return; fi
  if [[ $_nj_cur == -* && -n $sub ]]; then
    _nj_words "$opts"
    return
  fi
  if ((${#_nj_pos[@]} == 0)); then
    _nj_words "info list md5 package packages show"
    return
  fi
  case $sub in
    show | info | md5) _nj_ask "${kind}s" ;;
    package) if ((${#_nj_pos[@]} == 1)); then _nj_ask "$kind-packages"; fi ;;
    *) COMPREPLY=() ;;
  esac
}
_rosmsg() { _nj_interface_tool msg; }
_rossrv() { _nj_interface_tool srv; }

# -- rosbag --------------------------------------------------------------------------------------

_rosbag() {
  local sub opts="-h --help" values=""
  _nj_subcommand
  sub=$_nj_sub
  case $sub in
    record)
      opts="-h --help -a --all -e --regex -x --exclude -q --quiet -o --output-prefix -O --output-name
            --split --max-splits --size --duration -b --buffsize --chunksize -l --limit --node -j --bz2
            --lz4 --stats"
      values="-x --exclude -o --output-prefix -O --output-name --max-splits --size --duration -b
              --buffsize --chunksize -l --limit --node" ;;
    play)
      opts="-h --help -q --quiet -i --immediate --pause --queue --clock --hz -d --delay -r --rate -s
            --start -u --duration -l --loop -k --keep-alive --wait-for-subscribers --topics"
      values="--queue --hz -d --delay -r --rate -s --start -u --duration" ;;
    info) opts="-h --help -y --yaml -k --key --freq"; values="-k --key" ;;
    compress) opts="-h --help --output-dir -f --force -q --quiet -j --bz2 --lz4"; values="--output-dir" ;;
    decompress | reindex) opts="-h --help --output-dir -f --force -q --quiet"; values="--output-dir" ;;
    export) opts="-h --help --mcap -q --quiet" ;;
    filter) opts="-h --help -p" ;;
  esac
  _nj_parse "$values"
  case $_nj_optval in
    --node) _nj_ask nodes; return ;;
    -o | --output-prefix | -O | --output-name) _nj_files bag; return ;;
    --output-dir) compopt -o filenames 2>/dev/null; mapfile -t COMPREPLY < <(compgen -d -- "$_nj_cur"); return ;;
    "") ;;
    *) COMPREPLY=(); return ;;
  esac
  if [[ $_nj_cur == -* && -n $sub ]]; then
    _nj_words "$opts"
    return
  fi
  if ((${#_nj_pos[@]} == 0)); then
    _nj_words "check compress decompress export filter info play record reindex"
    return
  fi
  case $sub in
    record) _nj_ask topics ;;
    play)
      local i
      for ((i = 1; i < COMP_CWORD; i++)); do
        if [[ ${COMP_WORDS[i]} == --topics ]]; then _nj_ask topics; return; fi
      done
      _nj_files bag ;;
    export) if ((${#_nj_pos[@]} == 1)); then _nj_files bag; else _nj_files; fi ;;
    filter) if ((${#_nj_pos[@]} <= 2)); then _nj_files bag; else COMPREPLY=(); fi ;;
    *) _nj_files bag ;;
  esac
}

# -- rospack, rosversion, roscd, rosls, rosed ----------------------------------------------------

_rospack() {
  _nj_parse ""
  if ((${#_nj_pos[@]} == 0)); then
    _nj_words "depends depends-on depends-on1 depends1 find list list-names profile"
    [[ $_nj_cur == -* ]] && _nj_words "-h --help"
    return
  fi
  case ${_nj_pos[0]}:${#_nj_pos[@]} in
    find:1 | depends:1 | depends1:1 | depends-on:1 | depends-on1:1) _nj_ask packages ;;
    *) COMPREPLY=() ;;
  esac
}

_rosversion() {
  _nj_parse ""
  if [[ $_nj_cur == -* ]]; then _nj_words "-h --help -d --distro"; return; fi
  if ((${#_nj_pos[@]} == 0)); then _nj_ask packages; else COMPREPLY=(); fi
}

_roscd() {
  _nj_parse ""
  if ((${#_nj_pos[@]} == 0)); then _nj_ask pkg-dirs; else COMPREPLY=(); fi
}

_rosls() {
  _nj_parse ""
  if [[ $_nj_cur == -* ]]; then COMPREPLY=(); return; fi
  _nj_ask pkg-paths
}

_rosed() {
  _nj_parse ""
  if [[ $_nj_cur == -* ]]; then _nj_words "-h --help"; return; fi
  case ${#_nj_pos[@]} in
    0) _nj_ask packages ;;
    1) _nj_ask pkg-files "${_nj_pos[0]}" ;;
    *) COMPREPLY=() ;;
  esac
}

# -- rosrun, roslaunch ---------------------------------------------------------------------------

_rosrun() {
  _nj_parse "--prefix"
  if [[ -n $_nj_optval ]]; then COMPREPLY=(); return; fi
  if [[ $_nj_cur == -* && ${#_nj_pos[@]} -eq 0 ]]; then
    _nj_words "-h --help --prefix --debug"
    return
  fi
  case ${#_nj_pos[@]} in
    0) _nj_ask packages ;;
    1) _nj_ask executables "${_nj_pos[0]}" ;;
    *) _nj_words "$_NJ_NODE_ARGS"; _nj_nospace_dirs ;;
  esac
}

_roslaunch() {
  local values="--args --find-node -c --child -u --server_uri --run_id -p --port --pid"
  _nj_parse "$values"
  case $_nj_optval in
    --pid) _nj_files; return ;;
    "") ;;
    *) COMPREPLY=(); return ;;
  esac
  if [[ $_nj_cur == -* ]]; then
    _nj_words "-h --help --files --args --nodes --find-node -c --child --local --screen --required --log
               -u --server_uri --run_id --wait -p --port --core --pid -v --no-summary --dump-params"
    return
  fi
  local first=${_nj_pos[0]:-}
  if ((${#_nj_pos[@]} == 0)); then
    _nj_files launch test xml
    local -a files=("${COMPREPLY[@]}")
    _nj_ask packages
    COMPREPLY+=("${files[@]}")
    return
  fi
  if [[ -f $first ]]; then # roslaunch FILE... [arg:=value...]
    _nj_files launch test xml
    local -a args
    mapfile -t args < <(_nj_run launch-args "$first" "$_nj_cur")
    COMPREPLY+=("${args[@]}")
    _nj_nospace_dirs
    return
  fi
  if ((${#_nj_pos[@]} == 1)); then
    _nj_ask launch-files "$first"
  else
    _nj_ask launch-args "$first" "${_nj_pos[1]}"
  fi
}

# -- roscore, catkin -----------------------------------------------------------------------------

_roscore() {
  _nj_parse "-p --port -w --numworkers -t --timeout --master-logger-level"
  case $_nj_optval in
    --master-logger-level) _nj_words "debug info warn error fatal"; return ;;
    "") ;;
    *) COMPREPLY=(); return ;;
  esac
  _nj_words "-h --help -p --port -v -w --numworkers -t --timeout --master-logger-level"
}

_catkin_make() {
  _nj_parse "-C --directory --source --build -j --jobs"
  case $_nj_optval in
    -C | --directory | --source | --build)
      compopt -o filenames 2>/dev/null
      mapfile -t COMPREPLY < <(compgen -d -- "$_nj_cur")
      return ;;
    "") ;;
    *) COMPREPLY=(); return ;;
  esac
  if [[ $_nj_cur == -* ]]; then
    _nj_words "-h --help -C --directory --source --build --use-ninja --use-nmake --force-cmake --pkg
               --only-pkg-with-deps --cmake-args --make-args -j --jobs"
    return
  fi
  _nj_words "all clean install"
}

_catkin_create_pkg() {
  _nj_parse "-s --sys-deps -b --boost-comps -V --pkg_version -D --description -l --license -a --author
             -m --maintainer --rosdistro"
  if [[ -n $_nj_optval ]]; then COMPREPLY=(); return; fi
  if [[ $_nj_cur == -* ]]; then
    _nj_words "-h --help -s --sys-deps -b --boost-comps -V --pkg_version -D --description -l --license
               -a --author -m --maintainer --rosdistro --meta"
    return
  fi
  if ((${#_nj_pos[@]} == 0)); then COMPREPLY=(); else _nj_ask packages; fi
}

_catkin_init_workspace() {
  _nj_parse ""
  compopt -o filenames 2>/dev/null
  mapfile -t COMPREPLY < <(compgen -d -- "$_nj_cur")
}

# -- nodes started directly (turtlesim_node, rqt_graph, ...) -------------------------------------

_nj_node_command() {
  _nj_parse ""
  _nj_words "$_NJ_NODE_ARGS"
  _nj_nospace_dirs
}

complete -F _rostopic rostopic
complete -F _rosnode rosnode
complete -F _rosservice rosservice
complete -F _rosparam rosparam
complete -F _rosmsg rosmsg
complete -F _rossrv rossrv
complete -o default -F _rosbag rosbag
complete -F _rospack rospack
complete -F _rosversion rosversion
complete -o nospace -F _roscd roscd
complete -F _rosls rosls
complete -F _rosed rosed
complete -o default -F _rosrun rosrun
complete -F _roslaunch roslaunch
complete -F _roscore roscore
complete -F _catkin_make catkin_make
complete -F _catkin_create_pkg catkin_create_pkg
complete -F _catkin_init_workspace catkin_init_workspace
complete -F _nj_node_command turtlesim_node turtle_teleop_key rqt_graph
