"""What the ROS 2 bridge (roverlink/ros2/*.py) uses of rclpy and of the ROS messages, read from
its source with `ast`, for test_humble_api.py.

A small abstract interpreter: the names imported from rclpy and the message packages start typed
values, and assignments, attributes, calls, tuples, `self` attributes and callbacks
(`create_subscription`, `create_service`, `create_timer`) carry them, into the bridge's own
functions and classes too (with the arguments' types bound), since its converters take messages
duck-typed. Every attribute, keyword and field used on a typed value is a use, keyed as the
entries of humble_api.toml are ("rclpy.node.Node.create_publisher",
"rclpy.node.Node.create_timer(autostart=)", "nav_msgs/Odometry.child_frame_id"). What it cannot
type (the SDK's objects, `Any` without a known source) is not followed.
"""

from __future__ import annotations

import ast
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path

from ros_values import (
    CALLBACKS,
    MESSAGE_PACKAGES,
    Api,
    Bound,
    Msg,
    MsgModule,
    Own,
    Rcl,
    Seq,
    Srv,
    Super,
    Tup,
    Use,
    Value,
    options,
    union,
)


@dataclass
class _Function:
    key: str
    node: ast.FunctionDef | ast.AsyncFunctionDef
    module: str
    cls: str | None


@dataclass
class _Class:
    key: str
    node: ast.ClassDef
    module: str
    bases: list[Value] = field(default_factory=list)
    methods: dict[str, str] = field(default_factory=dict)
    attrs: dict[str, Value] = field(default_factory=dict)
    assigned: set[str] = field(default_factory=set)
    """The names assigned as `self.NAME = ...` anywhere in the class: its own, never rclpy's."""


class Analyzer:
    def __init__(self, api: Api, files: Iterable[Path], root: Path) -> None:
        self.api = api
        self.fields = api.message_fields()
        self._known = api.known()
        self.root = root
        self.uses: set[Use] = set()
        self.functions: dict[str, _Function] = {}
        self.classes: dict[str, _Class] = {}
        self.globals: dict[str, dict[str, Value]] = {}
        self._trees: dict[str, ast.Module] = {}
        self._paths: dict[str, Path] = {}
        self._memo: dict[tuple[str, tuple[tuple[str, Value], ...], Value], Value] = {}
        self._active: set[tuple[str, tuple[tuple[str, Value], ...], Value]] = set()
        self._module = ""
        for path in files:
            name = ".".join(path.relative_to(root).with_suffix("").parts)
            self._trees[name] = ast.parse(path.read_text(encoding="utf-8"), str(path))
            self._paths[name] = path
        for name, tree in self._trees.items():
            self._index(name, tree)

    # -- reading the modules ------------------------------------------------------------------------
    def _index(self, module: str, tree: ast.Module) -> None:
        for node in tree.body:
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                key = f"{module}.{node.name}"
                self.functions[key] = _Function(key, node, module, None)
            elif isinstance(node, ast.ClassDef):
                key = f"{module}.{node.name}"
                cls = self.classes[key] = _Class(key, node, module)
                cls.assigned = {
                    t.attr
                    for t in ast.walk(node)
                    if isinstance(t, ast.Attribute)
                    and isinstance(t.ctx, ast.Store)
                    and isinstance(t.value, ast.Name)
                    and t.value.id == "self"
                }
                for item in node.body:
                    if isinstance(item, ast.FunctionDef | ast.AsyncFunctionDef):
                        mkey = f"{key}.{item.name}"
                        cls.methods[item.name] = mkey
                        self.functions[mkey] = _Function(mkey, item, module, key)

    def run(self) -> set[Use]:
        """Every module's top level, then every function with its annotated parameters, twice (so
        attributes assigned in one method are known in the others)."""
        for module, tree in self._trees.items():
            self._module = module
            env = self.globals.setdefault(module, {})
            for cls in self.classes.values():
                if cls.module == module:
                    env[cls.node.name] = Own(cls.key)
            for fn in self.functions.values():
                if fn.module == module and fn.cls is None:
                    env[fn.node.name] = Own(fn.key)
            self._block([s for s in tree.body if not isinstance(s, ast.FunctionDef | ast.ClassDef)], env, [])
        for cls in self.classes.values():
            self._module = cls.module
            cls.bases = [self._eval(b, self.globals[cls.module]) for b in cls.node.bases]
        for _ in range(2):
            for fn in list(self.functions.values()):
                self._call_function(fn.key, {}, self_value=Own(fn.cls, True) if fn.cls else None)
        return self.uses

    # -- uses -------------------------------------------------------------------------------------------
    def _use(self, key: str, node: ast.AST) -> None:
        path = self._paths[self._module].relative_to(self.root)
        self.uses.add(Use(key, f"{path}:{getattr(node, 'lineno', 0)}"))

    def _attribute(self, value: Value, name: str, node: ast.AST) -> Value:
        """`value.name`; records the use. On a union, a name that some options have is looked up
        on those only (`msg.twist` of a Twist or a TwistStamped)."""
        found = [(o, self._lookup(o, name)) for o in options(value)]
        typed = [(o, k, v) for o, (k, v) in found if k is not None]
        known = [(o, k, v) for o, k, v in typed if k in self._known]
        for _, key, _ in known or typed:
            self._use(key, node)
        return union(*(v for _, _, v in known or typed), *(v for _, (k, v) in found if k is None))

    def _lookup(self, value: Value, name: str) -> tuple[str | None, Value]:
        """(the use's key, or None for nothing of ROS; the attribute's value)."""
        if isinstance(value, Rcl):
            key = f"{value.path}.{name}"
            entry = self.api.rclpy.get(key)
            if isinstance(entry, str):
                return key, self.api.type_of(entry)
            return key, Rcl(key)
        if isinstance(value, Msg):
            key = f"{value.name}.{name}"
            return key, self.api.type_of(self.fields.get(value.name, {}).get(name, ""))
        if isinstance(value, MsgModule):
            key = f"{value.package}/{name}"
            return key, Srv(key) if key in self.api.services else Msg(key, cls=True)
        if isinstance(value, Own):
            return self._own_attribute(value, name)
        if isinstance(value, Super):
            for base in self.classes[value.cls].bases:
                if isinstance(base, Rcl):  # super().__init__(...): the class's constructor
                    return (None, base) if name == "__init__" else self._lookup(Rcl(base.path, True), name)
                if isinstance(base, Own) and name in self.classes[base.key].methods:
                    return None, Bound(self.classes[base.key].methods[name], Own(value.cls, True))
        if isinstance(value, Seq) and name in ("append", "extend"):
            return None, None
        return None, None

    def _own_attribute(self, value: Own, name: str) -> tuple[str | None, Value]:
        if value.key in self._trees:  # a module of the bridge
            return None, self.globals.get(value.key, {}).get(name)
        cls = self.classes.get(value.key)
        if cls is None:
            return None, None
        for c in self._mro(cls):
            if name in c.methods:
                method = c.methods[name]
                return None, Bound(method, value) if value.instance else Own(method)
            if name in c.attrs or name in c.assigned:
                return None, c.attrs.get(name)
        for c in self._mro(cls):
            for base in c.bases:
                if isinstance(base, Rcl):
                    return self._lookup(Rcl(base.path, True), name)
        return None, None

    def _mro(self, cls: _Class) -> list[_Class]:
        out = [cls]
        for base in cls.bases:
            if isinstance(base, Own) and base.key in self.classes:
                out += self._mro(self.classes[base.key])
        return out

    # -- calls ------------------------------------------------------------------------------------------
    def _call(self, node: ast.Call, env: dict[str, Value]) -> Value:
        func = self._eval(node.func, env)
        args = [self._eval(a, env) for a in node.args]
        kwargs = {k.arg: self._eval(k.value, env) for k in node.keywords if k.arg is not None}
        if isinstance(node.func, ast.Name) and node.func.id in ("getattr", "setattr") and len(node.args) >= 2:
            name = node.args[1]
            if isinstance(name, ast.Constant) and isinstance(name.value, str):
                return self._attribute(args[0], name.value, node)
        if isinstance(node.func, ast.Attribute) and node.func.attr == "import_module" and node.args:
            arg = node.args[0]
            if isinstance(arg, ast.Constant) and str(arg.value).endswith((".msg", ".srv")):
                return MsgModule(str(arg.value).split(".")[0])
        results = [self._call_value(f, node, args, kwargs) for f in options(func)]
        return union(*results)

    def _call_value(self, func: Value, node: ast.Call, args: list[Value], kwargs: dict[str, Value]) -> Value:
        if isinstance(func, Rcl):
            for kw in kwargs:
                self._use(f"{func.path}({kw}=)", node)
            if func.path in CALLBACKS:
                self._callback(func.path, args, node)
            entry = self.api.rclpy.get(func.path)
            returns = entry.get("returns", "None") if isinstance(entry, dict) else "None"
            return self.api.type_of(returns)
        if isinstance(func, Msg) and func.cls:
            for kw in kwargs:
                self._use(f"{func.name}.{kw}", node)
            return Msg(func.name)
        if isinstance(func, Own) and func.key in self.classes:
            cls = self.classes[func.key]
            obj = Own(cls.key, True)
            for c in self._mro(cls):
                if "__init__" in c.methods:
                    self._call_function(
                        c.methods["__init__"], self._bind(c.methods["__init__"], args, kwargs, True), obj
                    )
                    break
            return obj
        if isinstance(func, Own) and func.key in self.functions:
            return self._call_function(func.key, self._bind(func.key, args, kwargs, False), None)
        if isinstance(func, Bound):
            return self._call_function(func.method, self._bind(func.method, args, kwargs, True), func.self_value)
        if isinstance(func, Super):
            return None
        return None

    def _callback(self, api: str, args: list[Value], node: ast.Call) -> None:
        type_index, callback_index = CALLBACKS[api]
        if callback_index >= len(args):
            return
        passed: list[Value] = []
        if type_index is not None and type_index < len(args):
            kind = args[type_index]
            msgs = [o for o in options(kind) if isinstance(o, Msg)]
            srvs = [o for o in options(kind) if isinstance(o, Srv)]
            if srvs:
                passed = [
                    union(*(Msg(f"{s.name}_Request") for s in srvs)),
                    union(*(Msg(f"{s.name}_Response") for s in srvs)),
                ]
            elif msgs:
                passed = [union(*(Msg(m.name) for m in msgs))]
        for cb in options(args[callback_index]):
            if isinstance(cb, Bound):
                self._call_function(cb.method, self._bind(cb.method, passed, {}, True), cb.self_value)

    def _bind(self, key: str, args: list[Value], kwargs: dict[str, Value], method: bool) -> dict[str, Value]:
        params = [a.arg for a in (*self.functions[key].node.args.posonlyargs, *self.functions[key].node.args.args)]
        if method:
            params = params[1:]
        bound = {p: v for p, v in zip(params, args, strict=False)}
        names = set(params) | {a.arg for a in self.functions[key].node.args.kwonlyargs}
        bound |= {k: v for k, v in kwargs.items() if k in names}
        return bound

    def _call_function(self, key: str, bound: dict[str, Value], self_value: Value) -> Value:
        fn = self.functions[key]
        args = sorted(((k, v) for k, v in bound.items() if v is not None), key=lambda kv: kv[0])
        memo = (key, tuple(args), self_value)
        if memo in self._memo or memo in self._active:
            return self._memo.get(memo)
        self._active.add(memo)
        module, self._module = self._module, fn.module
        env = dict(self.globals.get(fn.module, {}))
        a = fn.node.args
        params = [*a.posonlyargs, *a.args, *a.kwonlyargs]
        for i, p in enumerate(params):
            if i == 0 and fn.cls is not None:
                env[p.arg] = self_value
                continue
            env[p.arg] = bound.get(p.arg, self._annotation(p.annotation, env))
        returns: list[Value] = []
        self._block(fn.node.body, env, returns, fn.cls)
        self._module = module
        self._active.discard(memo)
        result = self._memo[memo] = union(*returns)
        return result

    def _annotation(self, node: ast.expr | None, env: dict[str, Value]) -> Value:
        """A parameter annotated with an rclpy class is an object of it (`node: Node`)."""
        if node is None:
            return None
        value = self._eval_quiet(node, env)
        return Rcl(value.path, True) if isinstance(value, Rcl) else None

    def _eval_quiet(self, node: ast.expr, env: dict[str, Value]) -> Value:
        if isinstance(node, ast.Name):
            return env.get(node.id)
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            try:
                return self._eval_quiet(ast.parse(node.value, mode="eval").body, env)
            except SyntaxError:
                return None
        return None

    # -- statements -------------------------------------------------------------------------------------
    def _block(self, body: list[ast.stmt], env: dict[str, Value], returns: list[Value], cls: str | None = None) -> None:
        for stmt in body:
            self._stmt(stmt, env, returns, cls)

    def _stmt(self, stmt: ast.stmt, env: dict[str, Value], returns: list[Value], cls: str | None) -> None:
        if isinstance(stmt, ast.Import | ast.ImportFrom):
            self._import(stmt, env)
        elif isinstance(stmt, ast.Assign):
            value = self._eval(stmt.value, env)
            for target in stmt.targets:
                self._assign(target, value, env, cls)
        elif isinstance(stmt, ast.AnnAssign | ast.AugAssign):
            value = self._eval(stmt.value, env) if stmt.value is not None else None
            self._assign(stmt.target, value, env, cls)
        elif isinstance(stmt, ast.Return):
            returns.append(self._eval(stmt.value, env) if stmt.value is not None else None)
        elif isinstance(stmt, ast.For | ast.AsyncFor):
            iterated = self._eval(stmt.iter, env)
            item = union(
                *(
                    i
                    for o in options(iterated)
                    for i in (o.items if isinstance(o, Tup) else (o.item,) if isinstance(o, Seq) else ())
                )
            )
            self._assign(stmt.target, item, env, cls)
            self._block(stmt.body + stmt.orelse, env, returns, cls)
        elif isinstance(stmt, ast.With | ast.AsyncWith):
            for item in stmt.items:
                value = self._eval(item.context_expr, env)
                if item.optional_vars is not None:
                    self._assign(item.optional_vars, value if isinstance(value, Own) else None, env, cls)
            self._block(stmt.body, env, returns, cls)
        elif isinstance(stmt, ast.FunctionDef | ast.AsyncFunctionDef):
            inner = dict(env)  # a closure sees the enclosing names
            for p in (*stmt.args.posonlyargs, *stmt.args.args, *stmt.args.kwonlyargs):
                inner[p.arg] = self._annotation(p.annotation, env)
            self._block(stmt.body, inner, [], cls)
        elif isinstance(stmt, ast.ClassDef):
            return  # indexed at the top level
        else:
            for child in ast.iter_child_nodes(stmt):
                if isinstance(child, ast.expr):
                    self._eval(child, env)
            for name in ("body", "orelse", "finalbody"):
                self._block(getattr(stmt, name, []), env, returns, cls)
            for handler in getattr(stmt, "handlers", []):
                if handler.type is not None:
                    self._eval(handler.type, env)
                self._block(handler.body, env, returns, cls)

    def _import(self, stmt: ast.Import | ast.ImportFrom, env: dict[str, Value]) -> None:
        if isinstance(stmt, ast.Import):
            for alias in stmt.names:
                top = alias.name.split(".")[0]
                if top == "rclpy":
                    env[alias.asname or top] = Rcl((alias.asname and alias.name) or top)
            return
        module = stmt.module or ""
        for alias in stmt.names:
            local = alias.asname or alias.name
            if module.split(".")[0] == "rclpy":
                key = f"{module}.{alias.name}"
                self._use(key, stmt)
                entry = self.api.rclpy.get(key)
                env[local] = self.api.type_of(entry) if isinstance(entry, str) else Rcl(key)
            elif module.endswith((".msg", ".srv")) and module.split(".")[0].endswith(MESSAGE_PACKAGES):
                key = f"{module.split('.')[0]}/{alias.name}"
                self._use(key, stmt)
                env[local] = Srv(key) if module.endswith(".srv") else Msg(key, cls=True)
            elif f"{module}.{alias.name}" in self._trees:
                env[local] = Own(f"{module}.{alias.name}")
            elif module in self._trees:
                env[local] = self.globals.get(module, {}).get(alias.name) or self._own_name(module, alias.name)

    def _own_name(self, module: str, name: str) -> Value:
        key = f"{module}.{name}"
        return Own(key) if key in self.classes or key in self.functions else None

    def _assign(self, target: ast.expr, value: Value, env: dict[str, Value], cls: str | None) -> None:
        if isinstance(target, ast.Name):
            env[target.id] = union(env.get(target.id), value) if target.id in env else value
        elif isinstance(target, ast.Tuple | ast.List):
            tup = next((o for o in options(value) if isinstance(o, Tup) and len(o.items) == len(target.elts)), None)
            for i, elt in enumerate(target.elts):
                self._assign(elt, tup.items[i] if tup else None, env, cls)
        elif isinstance(target, ast.Attribute):
            obj = self._eval(target.value, env)
            own = [o for o in options(obj) if isinstance(o, Own) and o.instance and o.key in self.classes]
            for o in own:
                attrs = self.classes[o.key].attrs
                attrs[target.attr] = union(attrs.get(target.attr), value)
            others = union(*(o for o in options(obj) if o not in own))
            if others is not None:
                self._attribute(others, target.attr, target)
        elif isinstance(target, ast.Subscript):
            self._eval(target.value, env)
            self._eval(target.slice, env)

    # -- expressions ------------------------------------------------------------------------------------
    def _eval(self, node: ast.expr, env: dict[str, Value]) -> Value:
        if isinstance(node, ast.Name):
            return env.get(node.id)
        if isinstance(node, ast.Attribute):
            return self._attribute(self._eval(node.value, env), node.attr, node)
        if isinstance(node, ast.Call):
            if isinstance(node.func, ast.Name) and node.func.id == "super":
                cls = next((c.key for c in self.classes.values() if self._encloses(c.node, node)), None)
                return Super(cls) if cls else None
            return self._call(node, env)
        if isinstance(node, ast.IfExp):
            self._eval(node.test, env)
            return union(self._eval(node.body, env), self._eval(node.orelse, env))
        if isinstance(node, ast.BoolOp):
            return union(*(self._eval(v, env) for v in node.values))
        if isinstance(node, ast.Tuple):
            return Tup(tuple(self._eval(e, env) for e in node.elts))
        if isinstance(node, ast.List):
            return Seq(union(*(self._eval(e, env) for e in node.elts)))
        if isinstance(node, ast.Subscript):
            base = self._eval(node.value, env)
            self._eval(node.slice, env)
            index = node.slice.value if isinstance(node.slice, ast.Constant) else None
            return union(
                *(
                    o.items[index]
                    if isinstance(o, Tup) and isinstance(index, int) and -len(o.items) <= index < len(o.items)
                    else o.item
                    if isinstance(o, Seq)
                    else None
                    for o in options(base)
                )
            )
        if isinstance(node, ast.NamedExpr):
            value = self._eval(node.value, env)
            env[node.target.id] = value
            return value
        if isinstance(node, ast.Lambda):
            inner = dict(env)
            self._eval(node.body, inner)
            return None
        if isinstance(node, ast.ListComp | ast.SetComp | ast.GeneratorExp | ast.DictComp):
            inner = dict(env)
            for gen in node.generators:
                iterated = self._eval(gen.iter, inner)
                item = union(*(o.item for o in options(iterated) if isinstance(o, Seq)))
                self._assign(gen.target, item, inner, None)
                for cond in gen.ifs:
                    self._eval(cond, inner)
            parts = [node.key, node.value] if isinstance(node, ast.DictComp) else [node.elt]
            results = [self._eval(p, inner) for p in parts]
            return Seq(results[-1]) if isinstance(node, ast.ListComp) else None
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.expr):
                self._eval(child, env)
            elif isinstance(child, ast.keyword):
                self._eval(child.value, env)
        return None

    def _encloses(self, cls: ast.ClassDef, node: ast.AST) -> bool:
        return any(n is node for n in ast.walk(cls))


def bridge_uses(api: Api, root: Path) -> set[Use]:
    """Every use of rclpy and of the messages in roverlink/ros2/*.py."""
    files = sorted((root / "roverlink" / "ros2").glob("*.py"))
    return Analyzer(api, files, root).run()
