"""The Excel case layer: template, reader, results written back, report workbook.

- :mod:`.layout`: the sheets and columns (one source of truth);
- :mod:`.sheets`: cells read by column kind and unit, problems collected;
- :mod:`.reader`: workbook -> case, runs and test data, with every problem;
- :mod:`.runs`: a Runs-sheet row and the case it asks for;
- :mod:`.template`: the template and ready cases, generated;
- :mod:`.writer`: result sheets written back, safely;
- :mod:`.report`: the report workbook with native charts;
- :mod:`.files`: atomic saves, lock files, content openpyxl would drop;
- :mod:`.execute`: the rows of a Runs sheet run.

Units are converted by :mod:`workbook.model.units`; the commands are in
:mod:`workbook.cli.workbooks`.
"""
