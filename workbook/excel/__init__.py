"""The Excel case layer: template, reader, results written back, report workbook.

- :mod:`.layout`: the sheets and columns (one source of truth);
- :mod:`.units`: unit cells converted to SI (pint);
- :mod:`.sheets`: cells read by column kind and unit, problems collected;
- :mod:`.reader`: workbook -> case, runs and test data, with every problem;
- :mod:`.runs`: a Runs-sheet row and the case it asks for;
- :mod:`.template`: the template and ready cases, generated;
- :mod:`.writer`: result sheets written back, safely;
- :mod:`.report`: the report workbook with native charts;
- :mod:`.files`: atomic saves, lock files, content openpyxl would drop;
- :mod:`.commands`: the ``mountwb check``, ``template`` and ``run CASE.xlsx`` commands.
"""
from .reader import CaseBook, Problem, WorkbookError, read_workbook
from .runs import RunSpec, TestPoint, case_for_run

__all__ = ["CaseBook", "Problem", "WorkbookError", "read_workbook", "RunSpec", "TestPoint", "case_for_run"]
