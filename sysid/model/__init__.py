"""Model structures (eq. 3.4): TOML files of named parameters and matrix entries, and their assembly."""

from .assemble import Assembler, SystemMatrices, structure_model
from .expression import Expression, parse_expression
from .structure import Constant, Entry, InputChannel, ModelStructure, Parameter
from .toml_format import builtin_structures, load_structure, parse_structure, read_structure

__all__ = [
    "Assembler", "SystemMatrices", "structure_model", "Expression", "parse_expression", "Constant", "Entry", "InputChannel",
    "ModelStructure", "Parameter", "builtin_structures", "load_structure", "parse_structure", "read_structure",
]
