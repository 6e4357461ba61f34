"""The exceptions rbsim raises (the extension module raises these classes)."""


class Error(Exception):
    """Any rbsim failure: an unreadable file, an output that exists, a refused command."""


class SceneError(Error, ValueError):
    """A scene file the loader refuses.

    The message is the loader's one line (``file:line: <node> attribute 'a': rule``); its parts
    are attributes too: ``file``, ``line`` (0 when the error has none, e.g. a missing file),
    ``node`` and ``attribute`` (empty when the rule is not about one) and ``rule``.
    """

    def __init__(self, message, file="", line=0, node="", attribute="", rule=""):
        super().__init__(message)
        self.file = file
        self.line = line
        self.node = node
        self.attribute = attribute
        self.rule = rule or message


class DivergenceError(Error, ArithmeticError):
    """The state became inf or NaN: the message names the step, the body and the quantity."""
