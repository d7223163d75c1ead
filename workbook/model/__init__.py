"""The case model: what the user asks for (engine, links, hinges, loads, excitations, effects),
its JSON form, units and the bundled reference mount."""
