"""Engine mount vibration isolation: cases, Exudyn scenes, answers and workbooks."""
