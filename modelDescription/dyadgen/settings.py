"""The settings of the FMU layer itself (fmu/fmu_model.h, fmu_setting): variables that no
model computes with, read by fmu_instance.c. A setting is an enumeration parameter; it
lives in ``fmu.<name>`` and its items are declared once, here, for the C table, both
model descriptions and the documentation."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Item:
    """One item of an enumeration: its name, value and meaning."""

    name: str
    value: int
    description: str


@dataclass(frozen=True)
class Setting:
    """A setting: its variable, its C name and its enumeration type."""

    name: str  # the variable's name, e.g. "on_singular"
    c_name: str  # its fmu_setting, e.g. "FMU_SETTING_ON_SINGULAR"
    type_name: str  # the declared type of both model descriptions
    type_description: str
    description: str  # the variable's
    items: tuple[Item, ...]
    start: int  # the default item's value

    @property
    def lives(self) -> str:
        """Where the variable lives: ``fmu.<name>``."""
        return f"fmu.{self.name}"

    @property
    def domain(self) -> dict:
        """The bounds the FMU layer checks a set value against: the items' values."""
        values = [item.value for item in self.items]
        return {"min": float(min(values)), "max": float(max(values))}


ON_SINGULAR = Setting(
    name="on_singular",
    c_name="FMU_SETTING_ON_SINGULAR",
    type_name="OnSingular",
    type_description="What doStep does at a sample where the model has no answer",
    description=(
        "What doStep does where the outputs are not defined (a singular position, a "
        "mechanism that cannot assemble, reactions that overflow): 1 discard, 2 continue "
        "with NaN outputs and the status set"
    ),
    items=(
        Item("discard", 1, "doStep returns Discard; the importer decides (the default)"),
        Item("continue", 2, "doStep returns OK; the outputs are NaN and status says why"),
    ),
    start=1,
)

#: Every setting, by name.
SETTINGS = {ON_SINGULAR.name: ON_SINGULAR}
