"""Model structures (eq. 3.4): TOML files of named parameters and matrix entries, and their assembly."""

from sysid.model.assemble import Assembler, SystemMatrices, structure_model
from sysid.model.axes import AxisPart, axis_parts, restrict_model
from sysid.model.expression import Expression, parse_expression
from sysid.model.structure import Constant, Entry, InputChannel, ModelStructure, Parameter
from sysid.model.toml_format import builtin_structures, load_structure, parse_structure, read_structure

__all__ = [
    "Assembler",
    "SystemMatrices",
    "structure_model",
    "AxisPart",
    "axis_parts",
    "restrict_model",
    "Expression",
    "parse_expression",
    "Constant",
    "Entry",
    "InputChannel",
    "ModelStructure",
    "Parameter",
    "builtin_structures",
    "load_structure",
    "parse_structure",
    "read_structure",
]
