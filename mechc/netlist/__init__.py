"""The netlist IR (cells joined by nets, held in a networkx graph) and the mapper onto it."""
