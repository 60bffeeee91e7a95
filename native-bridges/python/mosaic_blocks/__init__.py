"""Python modules behind the blocks that the original MOSAIC ran through Python.NET
(PythonNetFiltUC, PythonNetLearning, SimplePyTorch, iNMF). The TypeScript blocks
(app/blocks/learning/python-net-*.ts, simple-pytorch.ts, inmf.ts) load them into the Python
sidecar by module name (`mosaic_blocks.<module>`: native-bridges/python is on the sidecar's
PYTHONPATH); each follows the Python block's contract, `init(params) -> state` and
`fn(x, state) -> array`.
"""
