1LM3=2
1 2 3
4 5 6
ID=a
COMMENT=free text = ignored
LM3=2
0 0 0
1e1 -2.5E-1 7
