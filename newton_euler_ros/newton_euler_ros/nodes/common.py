# Copyright 2026 newton_euler_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
What every node of the package shares: parameters, QoS, and main().

``declare_parameters`` declares a node's parameters from its schema
(:mod:`..parameters`: ``<node>_parameters.yaml``) with their
descriptions and read-only flags, and validates them: a wrong type or an
invalid value is a :class:`ConfigurationError` (one line, exit status 2).

A parameter override (``-p`` or a params file) that no declared
parameter matches is a ConfigurationError too, naming the closest real
parameter; a ``--params-file`` with no section for the node's name gets a
warning naming the sections it has (its parameters then do not apply).
The parameters ROS 2 itself gives every node are not the node's to
refuse: ``use_sim_time`` and ``start_type_description_service`` (rclpy
declares them) and ``qos_overrides.<topic>.<publisher|subscription>.
<policy>``, which a robot bringup's shared ``/**:`` file sets for the
topics of every node.  :class:`SharedGraphNode` applies the QoS overrides
to the node's own publishers and subscriptions (history, depth,
reliability, durability; read-only, as in rclcpp) and ignores those
meant for other nodes' topics.

``run_node`` is the Jazzy-style main: init, build the node (a
configuration error refuses to start with a one-line reason and exit
status 2), spin until SIGINT/SIGTERM or shutdown, destroy, shut down;
a stop is exit status 0, also during start-up (one line).

Spinning uses rclpy's SingleThreadedExecutor through ``spin_once``:
its memory stays bounded by the subscriptions' QoS depth under any flood
of messages.  ``NEWTON_EULER_EXECUTOR=events`` chooses the experimental
EventsExecutor instead: ``make latency`` measures both side by side (it
uses about half the CPU and has a lower p99), but it queues one handler
per message it has not yet run, so a flood faster than the node's
callbacks grows its memory without bound until the flood stops.  The
EventsExecutor's ``spin()`` is avoided (in this rclpy build it busy-waits
and ignores shutdown).
"""
import array
import difflib
import os
import re
import signal
import sys
import warnings

from rcl_interfaces.msg import ParameterDescriptor
import rclpy
from rclpy.event_handler import PublisherEventCallbacks
from rclpy.exceptions import ParameterException
from rclpy.executors import ExternalShutdownException, \
    SingleThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import HistoryPolicy, QoSPolicyKind, QoSProfile, \
    ReliabilityPolicy
from rclpy.qos_overriding_options import InvalidQosOverridesError, \
    QoSOverridingOptions
from rclpy.signals import SignalHandlerOptions

from ..parameters import help_requested, print_help, validate

_PARAM_TYPES = {
    'string': Parameter.Type.STRING, 'double': Parameter.Type.DOUBLE,
    'int': Parameter.Type.INTEGER, 'bool': Parameter.Type.BOOL,
    'string_array': Parameter.Type.STRING_ARRAY,
    'double_array': Parameter.Type.DOUBLE_ARRAY,
}


class ConfigurationError(Exception):
    """A node's parameters are invalid; it refuses to start."""


def qos_profile(depth, reliability):
    """Return a QoS profile for a history depth and 'reliable'/'best_effort'."""
    return QoSProfile(depth=depth, reliability=(
        ReliabilityPolicy.RELIABLE if reliability == 'reliable'
        else ReliabilityPolicy.BEST_EFFORT))


def declare_parameter(node, name, default, descriptor):
    """
    Declare a parameter; a value of the wrong type is a ConfigurationError.

    rclpy raises InvalidParameterTypeException with a traceback when, say,
    ``-p wrench.timeout:=1`` gives an integer for a double: turn it into
    one line that says what to write.
    """
    try:
        return node.declare_parameter(name, default, descriptor)
    except ParameterException as exc:
        hint = ''
        if isinstance(default, float) or (
                isinstance(default, list) and default
                and isinstance(default[0], float)):
            hint = ' (write doubles with a decimal point, e.g. 1.0)'
        raise ConfigurationError(
            f'{name}: wrong type: {str(exc).splitlines()[0][:300]}'
            f'{hint}') from None


def seconds(stamp):
    """Return a message's time (builtin_interfaces Time, Duration) in s."""
    return stamp.sec + stamp.nanosec * 1e-9


def plain(value):
    """Return a parameter value with arrays (tuple, array.array) as lists."""
    if isinstance(value, (tuple, list, array.array)):
        return list(value)
    return value


# inverse_dynamics_node's publishers are created without rclpy's default
# QoS-event handlers (incompatible QoS or type): each publisher's handlers
# join the wait set that the executor rebuilds at every spin, which at
# 1 kHz measured more than the dynamics (the observer's three publishers
# took the node from 67 % to 95 % of a core).  A subscriber with an
# incompatible QoS still says so on its side; the node's subscriptions
# keep theirs.
QUIET = PublisherEventCallbacks(use_default_callbacks=False)

# the command line run_node gave rclpy.init (None: not run by run_node)
_PROCESS_ARGS = None
# --ros-args options that take a value (the value is not an option)
_ROS_VALUE_OPTIONS = {'-p', '--param', '-r', '--remap', '--params-file',
                      '--log-level', '--log-config-file', '-e', '--enclave'}


def params_files(args):
    """Return the ``--params-file`` paths of a command line, in order."""
    files = []
    in_ros = False
    tokens = iter(args or ())
    for token in tokens:
        if token == '--ros-args':
            in_ros = True
        elif token == '--':
            in_ros = False
        elif in_ros and token in _ROS_VALUE_OPTIONS:
            value = next(tokens, None)
            if token == '--params-file' and value is not None:
                files.append(value)
    return files


def params_file_sections(data):
    """
    Return the node sections of a parsed params file, as written.

    A section is the path of keys down to a ``ros__parameters`` mapping
    (``node``, ``/ns/node``, ``/**``, or nested ``ns: node:`` keys).
    """
    sections = []

    def walk(tree, path):
        for key, value in tree.items():
            if not isinstance(value, dict):
                continue
            if 'ros__parameters' in value:
                sections.append('/'.join([*path, str(key)]))
            walk({k: v for k, v in value.items()
                  if k != 'ros__parameters'}, [*path, str(key)])
    if isinstance(data, dict):
        walk(data, [])
    return sections


def section_matches(section, fully_qualified_name):
    """
    Return True when a params-file section applies to a node.

    ROS 2 rules: a name without a leading ``/`` gets one; ``*`` stands for
    one name token, ``**`` for any number of them (``/**``: every node).
    """
    tokens = [t for t in section.strip('/').split('/') if t]
    pattern = ''
    for token in tokens:
        if token == '**':
            pattern += '(/[^/]+)*'
        else:
            pattern += '/' + '[^/]+'.join(
                re.escape(part) for part in token.split('*'))
    return re.fullmatch(pattern or '/', fully_qualified_name) is not None


def _warn_foreign_params_files(node):
    """Warn about params files without a section for this node."""
    import yaml
    fqn = node.get_fully_qualified_name()
    for path in params_files(_PROCESS_ARGS):
        try:
            with open(path, encoding='utf-8') as fh:
                loader = getattr(yaml, 'CSafeLoader', yaml.SafeLoader)
                data = yaml.load(fh, Loader=loader)
        except (OSError, yaml.YAMLError, UnicodeDecodeError):
            continue            # rcl has already said what is wrong
        sections = params_file_sections(data)
        if not any(section_matches(s, fqn) for s in sections):
            node.get_logger().warning(
                f'params file {path}: no section for this node ({fqn}); its '
                f'sections: {", ".join(sections) or "none"}; none of its '
                f'parameters apply (name a section {node.get_name()}: or '
                f'/**:)')


#: parameters rclpy declares on every node (its clock, its type
#: description service): a shared params file may set them for all nodes
RCLPY_PARAMETERS = ('use_sim_time', 'start_type_description_service')
#: prefix of ROS 2's QoS override parameters
QOS_OVERRIDES = 'qos_overrides.'
#: the policies a qos_overrides entry may set on the nodes' topics
QOS_POLICIES = (QoSPolicyKind.HISTORY, QoSPolicyKind.DEPTH,
                QoSPolicyKind.RELIABILITY, QoSPolicyKind.DURABILITY)


def ros_parameter(name):
    """Return True for a parameter that ROS 2 owns, not the node."""
    return name in RCLPY_PARAMETERS or name.startswith(QOS_OVERRIDES)


def _check_qos(qos):
    from rcl_interfaces.msg import SetParametersResult
    if qos.history == HistoryPolicy.KEEP_LAST and qos.depth < 1:
        return SetParametersResult(
            successful=False, reason=f'depth must be >= 1 with history '
            f'keep_last, got {qos.depth}')
    return SetParametersResult(successful=True)


class SharedGraphNode(Node):
    """
    A Node whose topics take ROS 2's ``qos_overrides`` parameters.

    Every publisher and subscription the node creates after its
    construction declares ``qos_overrides.<topic>.<kind>.<policy>`` for
    history, depth, reliability and durability (read-only), as rclcpp's
    ``QosOverridingOptions`` does: a value from a params file replaces the
    node's own QoS for that topic.  A bad value (``reliability: sure``,
    ``depth: 0``) is a ConfigurationError naming the parameter.
    """

    def __init__(self, node_name, **kwargs):
        super().__init__(node_name, **kwargs)
        # not for what Node.__init__ creates (/parameter_events)
        self._qos_overridable = True

    def create_publisher(self, msg_type, topic, qos_profile, **kwargs):
        """Create a publisher whose QoS a qos_overrides entry can set."""
        return self._overridable(super().create_publisher, 'publisher',
                                 topic, (msg_type, topic, qos_profile),
                                 kwargs)

    def create_subscription(self, msg_type, topic, callback, qos_profile,
                            **kwargs):
        """Create a subscription whose QoS a qos_overrides entry can set."""
        return self._overridable(super().create_subscription,
                                 'subscription', topic,
                                 (msg_type, topic, callback, qos_profile),
                                 kwargs)

    def _overridable(self, create, kind, topic, args, kwargs):
        if not getattr(self, '_qos_overridable', False) or \
                'qos_overriding_options' in kwargs:
            return create(*args, **kwargs)
        prefix = f'{QOS_OVERRIDES}{self.resolve_topic_name(topic)}.{kind}.'
        given = sorted(name for name in getattr(
            self, '_parameter_overrides', {}) if name.startswith(prefix))
        options = QoSOverridingOptions(QOS_POLICIES, callback=_check_qos)
        try:
            with warnings.catch_warnings():     # depth 0: said below
                warnings.simplefilter('ignore', UserWarning)
                entity = create(*args, qos_overriding_options=options,
                                **kwargs)
        except (InvalidQosOverridesError, ParameterException,
                RuntimeError, ValueError) as exc:
            if not given:
                raise
            reason = (str(exc) or type(exc).__name__).splitlines()[0]
            reason = reason.split('are not valid: ')[-1]
            raise ConfigurationError(
                f'{", ".join(given)}: {reason[:300]}') from None
        if given:
            values = ', '.join(
                f'{name[len(prefix):]} {self.get_parameter(name).value}'
                for name in given if self.has_parameter(name))
            self.get_logger().info(
                f'qos_overrides: {prefix[len(QOS_OVERRIDES):-1]}: {values}')
        return entity

    def create_tick_timer(self, period, tick, **kwargs):
        """
        Create a timer calling ``tick``; an error after shutdown is quiet.

        On SIGINT the context closes while a tick may still publish: that
        publish fails, and is not an error of the node.  Any other
        exception is raised.
        """
        def call():
            try:
                tick()
            except Exception:
                if self.context.ok():
                    raise
        return self.create_timer(period, call, **kwargs)


def check_overrides(node, specs):
    """
    Refuse parameter overrides that no parameter of ``specs`` matches.

    rclpy drops an override (``-p`` or a params file) that is never
    declared without a word; raise a ConfigurationError naming it and the
    closest real parameter instead.  The parameters ROS 2 owns
    (:func:`ros_parameter`) are not the node's to refuse.  Also warns
    about params files that have no section for this node.
    """
    _warn_foreign_params_files(node)
    names = [spec.name for spec in specs]
    overrides = getattr(node, '_parameter_overrides', None) or {}
    unknown = [name for name in overrides
               if name not in names and not node.has_parameter(name)
               and not ros_parameter(name)]
    reasons = []
    for name in sorted(unknown):
        close = difflib.get_close_matches(name, names, n=1, cutoff=0.5)
        hint = (f'did you mean {close[0]!r}?' if close else
                f'{node.get_name()} --help lists the parameters')
        reasons.append(f'unknown parameter {name[:100]!r} ({hint})')
    if reasons:
        raise ConfigurationError('; '.join(reasons))


def declare_parameters(node, specs):
    """
    Declare every parameter of ``specs`` on ``node``; return their values.

    ``specs`` is a list of :class:`..parameters.ParameterSpec`.  Each gets
    its description and read-only flag; the values (defaults or
    overrides, arrays as lists) are validated against the schema's rules.
    A wrong type, an invalid value or an override that matches no
    parameter (:func:`check_overrides`) raises ConfigurationError.
    """
    check_overrides(node, specs)
    values = {}
    for spec in specs:
        desc = ParameterDescriptor(description=spec.description,
                                   read_only=spec.read_only)
        if spec.default == [] or spec.default == '':
            # an empty default does not tell rclpy the type
            declare_parameter(node, spec.name, _PARAM_TYPES[spec.type], desc)
            param = node.get_parameter_or(spec.name, None)
            value = param.value if param is not None else None
            values[spec.name] = spec.default if value is None else value
        else:
            values[spec.name] = declare_parameter(
                node, spec.name, spec.default, desc).value
        values[spec.name] = plain(values[spec.name])
    errors = validate(values, specs)
    if errors:
        raise ConfigurationError('; '.join(errors))
    return values


def check_parameters(params, specs):
    """
    Validate parameters set at run time: (values, reasons).

    ``values`` maps each name to its plain value; ``reasons`` is '' when
    every value passes the schema's rules, else why not (one line).
    """
    values = {param.name: plain(param.value) for param in params}
    return values, '; '.join(validate(values, specs))


def _libc_trim():
    try:
        import ctypes
        return ctypes.CDLL('libc.so.6').malloc_trim
    except (OSError, AttributeError):        # not glibc: nothing to do
        return None


_MALLOC_TRIM = _libc_trim()


def release_memory():
    """
    Give freed heap back to the operating system (glibc ``malloc_trim``).

    Under a flood of messages the EventsExecutor (when chosen) queues one
    small handler per message it has not yet run; once the flood is over
    they are freed, but glibc keeps the pages, so the process' RSS would
    stay at its peak.
    Nodes call this from their periodic timer: about 0.1 ms.
    """
    if _MALLOC_TRIM is not None:
        _MALLOC_TRIM(0)


EXECUTORS = ('single_threaded', 'events')


class KernelTimer:
    """
    Say, once per node, what loading the compiled kernels costs.

    Before the first model is built: a warning when the kernels were not
    compiled ahead for these sources (``python -m
    newton_euler_ros.precompile``, which ``make setup`` runs), since the
    node is then silent for a minute or more while numba compiles them.
    After: how long it took.  ``start()`` and ``done(logger)`` bracket
    the first build; later builds say nothing.
    """

    def __init__(self, logger):
        self.logger = logger
        self.started = None
        self.said = False

    def start(self):
        """Call before the first build: warns if a compile is coming."""
        import time
        if self.said or self.started is not None:
            return
        from ..precompile import stamp_path
        self.precompiled = os.path.exists(stamp_path())
        if not self.precompiled:
            self.logger.warning(
                'the kernels were not compiled ahead for this install: '
                'compiling what this node needs now (a minute or more on '
                'a 2-core machine; nothing is published meanwhile). '
                '"python -m newton_euler_ros.precompile" does it once, '
                'ahead of time (make setup runs it)')
        self.started = time.monotonic()

    def done(self):
        """Call after the first build: the time it took, said once."""
        import time
        if self.said or self.started is None:
            return
        self.said = True
        took = time.monotonic() - self.started
        how = ('loaded from the cache' if self.precompiled
               else 'compiled, or loaded where the cache had them')
        self.logger.info(f'kernels ready in {took:.1f} s ({how})')


def make_executor(kind=None, context=None):
    """
    Return the executor ``kind`` names, for ``context`` (None: default).

    ``kind`` is 'single_threaded' or 'events'; None reads
    ``NEWTON_EULER_EXECUTOR`` (default single_threaded).  Without an
    EventsExecutor in this rclpy, 'events' gives the single-threaded one;
    ``type(executor).__name__`` says which.
    """
    if kind is None:
        kind = os.environ.get('NEWTON_EULER_EXECUTOR') or 'single_threaded'
    if kind not in EXECUTORS:
        raise ConfigurationError(
            f'NEWTON_EULER_EXECUTOR must be one of {", ".join(EXECUTORS)}, '
            f'got {kind[:80]!r}')
    if kind == 'events':
        try:
            from rclpy.experimental import EventsExecutor
            return EventsExecutor(context=context)
        except ImportError:
            pass
    return SingleThreadedExecutor(context=context)


def run_node(make_node, name, args=None):
    """Run a node until shutdown; return the process exit status."""
    # SIGINT and SIGTERM only ask for a stop: the spin loop ends within
    # one spin period, and a stop asked for during start-up (while the
    # node loads its model and warms its kernels) waits for the
    # constructor.  rclpy's own handlers would shut the context down under
    # the constructor or a publishing callback (RCLError tracebacks).
    global _PROCESS_ARGS
    argv = sys.argv if args is None else args
    if help_requested(argv):
        print_help(name)
        return 0
    _PROCESS_ARGS = list(argv)
    stop = []
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda signum, frame: stop.append(signum))
    try:
        rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    except Exception as exc:  # e.g. malformed --ros-args: say so, briefly
        print(f'{name}: cannot start: {exc}'.splitlines()[0],
              file=sys.stderr)
        return 2
    node = None
    code = 0
    try:
        executor = make_executor()
        if not stop:
            node = make_node()
        if stop:
            print(f'{name}: stopped during start-up '
                  f'({signal.Signals(stop[0]).name})', file=sys.stderr)
            return 0
        executor.add_node(node)
        while rclpy.ok() and not stop:
            executor.spin_once(timeout_sec=0.1)
    except ConfigurationError as exc:
        print(f'{name}: invalid configuration: {exc}', file=sys.stderr)
        code = 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        if node is not None:
            node.destroy_node()
        rclpy.try_shutdown()
    return code
