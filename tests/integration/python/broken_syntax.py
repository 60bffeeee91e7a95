"""A module with a syntax error on line 5 (tests/integration/python.test.ts)."""


def predict(x):
    return x +
